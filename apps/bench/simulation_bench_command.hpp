#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench simulation`: the time per frame of each simulation effect.
void AddSimulationBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
