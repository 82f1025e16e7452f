#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// Adds `bench triangulation` and `bench deformation` under `bench`.
void AddBenchCommands(CLI::App& bench);

// `uwscan demo`: the main job on the embedded default scanner.
void AddDemoCommand(CLI::App& app);

}  // namespace uwscan::app
