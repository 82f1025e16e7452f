#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `bench accuracy`: the seeds' accuracy experiments in simulation (gauges, plane, sphere,
// waypoints per line).
void AddAccuracyBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
