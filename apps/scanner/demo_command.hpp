#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `demo`: simulates the default scene, reconstructs it with every triangulation method the
// scanner has and prints each one's accuracy against ground truth and its time.
void AddDemoCommand(CLI::App& app);

}  // namespace uwscan::app
