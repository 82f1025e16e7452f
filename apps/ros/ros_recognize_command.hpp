#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan ros recognize`: recognition as a ROS 1 node (ros/node/recognition_node.hpp), added
// under `ros`.
void AddRosRecognizeCommand(CLI::App& ros);

}  // namespace uwscan::app
