#pragma once

#include <filesystem>

#include "ros/bag/bag_export.hpp"
#include "ros/bridge/bag_file.hpp"

// A map report (`uwscan map --json`, docs/formats.md "Map report") written into a bag, so that
// a mapped dive replays in RViz: the map (latched, from the start), and at each submap anchor
// the SLAM, navigation and (simulated dives) true paths up to it, the pose with its covariance
// and the correction map -> odom, on the topics the node publishes (ros_names.hpp).
namespace uwscan::ros {

struct ReportExportSummary {
  std::int64_t anchors = 0;
  std::int64_t map_points = 0;
  bool truth = false;
};

// ROS time = report time + time_origin_s (the origin ExportToBag takes for the report's dive
// log). Throws uwscan::Error naming the report and the field when it is not a map
// report, a field is missing or malformed, or its map cannot be read.
ReportExportSummary ExportMapReport(const std::filesystem::path& report, double time_origin_s,
                                    const BagExportOptions& options, BagWriter& bag);

}  // namespace uwscan::ros
