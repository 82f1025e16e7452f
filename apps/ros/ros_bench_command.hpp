#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench ros`: the ROS node end to end against `inspect` on the same dive.
void AddRosBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
