#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench threads`: uwscan's OpenMP commands timed with 1 and 2 threads under both wait
// policies, idle and with another process busy on the last CPU (bench/thread_load_benchmark).
void AddThreadBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
