#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ros/bridge/messages.hpp"
#include "ros/conversions/ros_names.hpp"

// Where the vehicle's navigation comes from and in which axes, so that uwscan takes a vehicle's
// navigation as its software publishes it. uwscan works in NED (world) and forward-right-down
// (vehicle) axes, as marine vehicles running ROS publish them (REP 103 allows it); stacks that
// follow REP 103's default (robot_localization: ENU world, forward-left-up vehicle) are turned
// into uwscan's axes as they come, and so is the camera's mount, which they give from a
// forward-left-up base_link.
namespace uwscan::ros {

enum class NavigationSource {
  kOdometry,  // nav_msgs/Odometry on RosTopics::odometry
  kTf,        // the odom -> base_link transforms on /tf (RosFrames' names)
};

enum class NavigationAxes {
  kNedFrd,  // uwscan's own: taken as given
  kEnuFlu,  // REP 103's default
};

struct NavigationInput {
  NavigationSource source = NavigationSource::kOdometry;
  NavigationAxes axes = NavigationAxes::kNedFrd;
};

// "odometry" | "tf" and "ned" | "enu"; throws uwscan::Error naming `what` and the choices.
NavigationSource ParseNavigationSource(const std::string& text, const std::string& what);
NavigationAxes ParseNavigationAxes(const std::string& text, const std::string& what);
std::string ToString(NavigationSource source);
std::string ToString(NavigationAxes axes);

// T_odom_base_link in uwscan's axes from one in `axes`.
Eigen::Isometry3d VehiclePoseInUwscanAxes(const Eigen::Isometry3d& T_odom_base,
                                          NavigationAxes axes);
// The camera's mount T_base_link_camera with base_link in uwscan's axes (the camera frame is
// OpenCV's in both).
Eigen::Isometry3d MountInUwscanAxes(const Eigen::Isometry3d& T_base_camera, NavigationAxes axes);

// And back, for what uwscan publishes in the navigation's world frame (map, paths, poses):
// T_W_V in `axes`, a world point in `axes`, and a covariance over (position, rotation about the
// world's axes) with both blocks on `axes`'s world axes.
Eigen::Isometry3d VehiclePoseInNavigationAxes(const Eigen::Isometry3d& T_W_V, NavigationAxes axes);
Eigen::Vector3d WorldPointInNavigationAxes(const Eigen::Vector3d& p_W, NavigationAxes axes);
Covariance6d WorldCovarianceInNavigationAxes(const Covariance6d& c, NavigationAxes axes);

// The navigation sample among `transforms` (one /tf message): the transform from frames.odom to
// frames.base_link as odometry without covariance; none when the message has no such transform.
std::optional<OdometryMessage> NavigationFromTransforms(
    const std::vector<TransformMessage>& transforms, const RosFrames& frames);

}  // namespace uwscan::ros
