#pragma once

#include <string>
#include <vector>

namespace uwscan::app {

// Throws uwscan::Error naming the first argument that is not a ROS remapping or private
// parameter (name:=value), the only extras the ROS commands take.
void CheckRosArguments(const std::vector<std::string>& arguments);

}  // namespace uwscan::app
