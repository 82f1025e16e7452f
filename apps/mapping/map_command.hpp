#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan map DIVE.db -o MAP.ply [--trajectory SLAM.tum] [--dead-reckoning DR.tum] [--truth T.tum]
// [--json REPORT.json]`: scan-matching SLAM over a dive log.
void AddMapCommand(CLI::App& app);

}  // namespace uwscan::app
