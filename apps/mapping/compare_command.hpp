#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan compare MAP --reference CAD.ply|OLD_MAP.ply|MAP_REPORT.json -o DEVIATIONS.ply
// [--json REPORT.json] [--markdown REPORT.md]`: what the inspection found.
void AddCompareCommand(CLI::App& app);

}  // namespace uwscan::app
