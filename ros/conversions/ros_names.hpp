#pragma once

#include <string>

// The topics and frames uwscan reads and writes on ROS, with defaults a user overrides (bag
// options, or the node's private parameters). Frames follow REP 105 by name (map, odom,
// base_link, a sensor frame); their axes are uwscan's (DESIGN.md): the world frames are NED and
// the vehicle frame is forward-right-down, as marine vehicles running ROS publish them (REP 103
// allows NED frames for marine use), and the camera frame is OpenCV's (x right, y down, z
// forward).
namespace uwscan::ros {

struct RosTopics {
  std::string frames =
      "/uwscan/frames";  // sensor_msgs/Image: profile or image payload (frame_image.hpp)
  std::string odometry = "/navigation/odometry";  // nav_msgs/Odometry: T_odom_base_link
  std::string dive = "/uwscan/dive";  // std_msgs/String: DiveDescription (YAML), latched
  std::string tf = "/tf";
  std::string tf_static = "/tf_static";
  // What uwscan publishes.
  std::string sweeps = "/uwscan/sweep";    // sensor_msgs/PointCloud2, camera frame
  std::string map = "/uwscan/map";         // sensor_msgs/PointCloud2, map frame, latched
  std::string slam_path = "/uwscan/path";  // nav_msgs/Path, map frame
  std::string navigation_path = "/uwscan/navigation_path";  // nav_msgs/Path, map frame
  std::string truth_path = "/uwscan/truth_path";  // nav_msgs/Path, map frame (simulated dives)
  std::string pose = "/uwscan/pose";  // geometry_msgs/PoseWithCovarianceStamped, map frame
  // Recognition's (object_messages.hpp), in the camera frame.
  std::string objects = "/uwscan/objects";            // visualization_msgs/MarkerArray, latched
  std::string object_poses = "/uwscan/object_poses";  // geometry_msgs/PoseWithCovarianceStamped
  std::string grasps = "/uwscan/grasps";              // geometry_msgs/PoseArray, latched
};

struct RosFrames {
  std::string map = "map";
  std::string odom = "odom";
  std::string base_link = "base_link";
  std::string camera = "uwscan_camera";
};

}  // namespace uwscan::ros
