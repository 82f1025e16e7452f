#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "ros/conversions/ros_names.hpp"
#include "scanner/acquisition/frame_encoding.hpp"

// A dive log written as a ROS 1 bag, as the vehicle would have recorded it: the camera's frames
// as images (frame_image.hpp), the navigation as nav_msgs/Odometry and on /tf, the camera's
// mount on /tf_static and the scanner in the dive description (dive_description.hpp), so that
// `uwscan bag import` needs no --scanner and `rosbag play` feeds `uwscan ros inspect`.
namespace uwscan::ros {

struct BagExportOptions {
  RosTopics topics;
  RosFrames frames;
  std::string producer;  // recorded in the dive description ("uwscan bag export 0.1.0")
};

struct BagExportSummary {
  std::int64_t frames = 0;
  std::int64_t images = 0;  // of them, sent as images (the log kept them); the rest as profiles
  std::int64_t navigation = 0;
  double time_origin_s = 0.0;  // ROS time of the log's time 0
  scanner::acquisition::ProfileLayout layout;
};

// Writes `bag` (which must not exist) from `log`. A log whose times are not Unix times (a
// simulated dive counts from 0) is placed at its creation time: ROS time = log time +
// time_origin_s. Throws uwscan::Error naming the file on any failure; the bag is then removed.
BagExportSummary ExportDiveLog(const std::filesystem::path& log, const std::filesystem::path& bag,
                               const BagExportOptions& options);

}  // namespace uwscan::ros
