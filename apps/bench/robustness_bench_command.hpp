#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench robustness`: every reader of outside data fed mutated files (each read in a
// child process), and dive logs damaged by random bytes; `--write-seeds DIR` writes the seed
// files alone (the fuzzers' corpora).
void AddRobustnessBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
