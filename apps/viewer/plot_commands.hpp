#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `plot REPORT.json -o FIG.png`: the trade-off charts of a bench's JSON.
void AddPlotCommand(CLI::App& app);
// `report -o DIR`: runs the benches in their quick forms and writes DIR/index.md with each
// table and its chart.
void AddReportCommand(CLI::App& app);
// `bench viewer`: time to the first picture, per frame, and memory, for 1 M and 5 M points.
void AddViewerBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
