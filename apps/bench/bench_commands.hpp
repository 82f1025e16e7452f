#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// Adds `bench triangulation` and `bench deformation` under `bench`.
void AddBenchCommands(CLI::App& bench);

}  // namespace uwscan::app
