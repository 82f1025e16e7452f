#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace uwscan::app {

// A pose given on the command line in TUM order, "tx ty tz qx qy qz qw" (the quaternion of unit
// length), or, where `position_alone` allows it, "tx ty tz" (axes unturned). Throws uwscan::Error
// naming `option` when the count is wrong, a number is not finite or the quaternion is not unit.
Eigen::Isometry3d ParsePoseOption(const std::vector<double>& values, const std::string& option,
                                  bool position_alone = false);

}  // namespace uwscan::app
