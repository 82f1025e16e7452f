#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bag import` and `uwscan bag export`: ROS 1 bags to dive logs and back.
void AddBagCommands(CLI::App& app);

}  // namespace uwscan::app
