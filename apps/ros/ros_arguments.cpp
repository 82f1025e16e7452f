#include "apps/ros/ros_arguments.hpp"

#include "scanner/common/error.hpp"

namespace uwscan::app {

void CheckRosArguments(const std::vector<std::string>& arguments) {
  for (const std::string& argument : arguments) {
    if (argument.find(":=") == std::string::npos) {
      throw Error("unexpected argument '" + argument +
                  "' (ROS remappings and parameters are name:=value)");
    }
  }
}

}  // namespace uwscan::app
