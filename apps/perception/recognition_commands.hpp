#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan build-db MESH|SHAPE... -o objects.db [--views N] [--scanner FILE]`: the object
// database recognition searches, made by the virtual scanner.
void AddBuildDbCommand(CLI::App& app);

// `uwscan recognize SCAN.ply|SCAN.pcd|DIVE.db --db objects.db [--json FILE]`: object ids, poses,
// free directions and grasp poses in the scan's frame.
void AddRecognizeCommand(CLI::App& app);

}  // namespace uwscan::app
