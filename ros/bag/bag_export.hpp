#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "ros/conversions/ros_names.hpp"
#include "scanner/acquisition/frame_encoding.hpp"

// Dive logs, map reports and recognition reports written as one ROS 1 bag. A dive log goes in as
// the vehicle would have recorded it: the camera's frames as images (frame_image.hpp), the
// navigation as nav_msgs/Odometry and on /tf, the camera's mount on /tf_static and the scanner in
// the dive description (dive_description.hpp), so that `uwscan bag import` needs no --scanner and
// `rosbag play` feeds `uwscan ros inspect`. A map report goes in as the node would have published
// it (report_export.hpp), so that a mapped dive replays in RViz; a recognition report as
// `uwscan ros recognize` would have (recognition_export.hpp).
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
  std::int64_t anchors = 0;      // map reports' submap anchors
  std::int64_t map_points = 0;   // map reports' maps
  std::int64_t scan_points = 0;  // recognition reports' scans
  std::int64_t objects = 0;      // recognition reports' recognised objects
  std::int64_t grasps = 0;
  double time_origin_s = 0.0;  // ROS time of the logs' time 0
  scanner::acquisition::ProfileLayout layout;
};

// Writes `bag` (which must not exist) from `inputs`: dive logs (SQLite), map and recognition
// reports (JSON), told apart by their content. Times: ROS time = log time + time_origin_s, where
// the origin is 0 for a log whose times are Unix times and its creation time for one that counts
// from 0 (a simulated dive): the first dive log's, else that of the log a report names (a map
// report's log, a recognition report's scan). Throws uwscan::Error naming the file on any failure;
// the bag is then removed.
BagExportSummary ExportToBag(const std::vector<std::filesystem::path>& inputs,
                             const std::filesystem::path& bag, const BagExportOptions& options);

}  // namespace uwscan::ros
