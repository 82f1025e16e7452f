#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `bench stripe` under `bench`: speed and sub-pixel accuracy of every stripe detector.
void AddStripeBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
