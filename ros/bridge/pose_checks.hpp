#pragma once

#include <string>

#include "ros/bridge/messages.hpp"

// Poses and covariances as ROS messages carry them, checked before uwscan takes them: shared by
// the conversions of subscribed messages (message_conversions) and the bag reader's own message
// decoding (bag_message_decoding), so both refuse the same values with the same words. C++17, no
// ROS include.
namespace uwscan::ros {

// T_parent_child from a ROS position and quaternion. Throws uwscan::Error "WHAT: a pose value is
// not finite" or "WHAT: orientation is not a unit quaternion (norm N)" (within 1e-3).
Eigen::Isometry3d PoseFromRosValues(double x, double y, double z, double qx, double qy, double qz,
                                    double qw, const std::string& what);

// A 6x6 covariance from ROS's 36 row-major values. Throws uwscan::Error naming the value that is
// not finite.
Covariance6d CovarianceFromRosValues(const double* values, const std::string& what);

}  // namespace uwscan::ros
