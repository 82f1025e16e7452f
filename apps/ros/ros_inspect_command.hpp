#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan ros inspect`: online inspection as a ROS 1 node (ros/node/inspection_node.hpp).
void AddRosCommands(CLI::App& app);

}  // namespace uwscan::app
