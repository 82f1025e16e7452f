#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `simulate SCENE.yaml -o DIVE.db [--images]`: a simulated dive into a new dive log.
void AddSimulateCommand(CLI::App& app);
// `reconstruct DIVE.db -o CLOUD.ply [--method plane|cone|ray]`: a dive log into a point cloud.
void AddReconstructCommand(CLI::App& app);

}  // namespace uwscan::app
