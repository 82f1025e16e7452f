#pragma once

#include <cstdint>
#include <filesystem>

#include "ros/bag/bag_export.hpp"
#include "ros/bridge/bag_file.hpp"

// A recognition report (`uwscan recognize --json`, docs/formats.md "Recognition report") written
// into a bag as `uwscan ros recognize` would have published it, so that what was recognised
// replays in RViz: the scan on the sweep topic, and on recognition's topics each object's pose
// with its covariance, every grasp, and the models at their poses with their labels
// (object_messages.hpp), all in the camera frame at the scan's time.
namespace uwscan::ros {

struct RecognitionExportSummary {
  std::int64_t scan_points = 0;
  std::int64_t objects = 0;  // recognised (unknown segments are not drawn)
  std::int64_t grasps = 0;
};

// The scan's time: the middle of its sweep's frames (the instant its points are given at) for a
// dive log, plus time_origin_s (the origin ExportToBag takes); time_origin_s for a cloud file.
// Throws uwscan::Error naming the report, its scan or its database when one cannot be read, or
// when the database lacks a recognised object.
RecognitionExportSummary ExportRecognitionReport(const std::filesystem::path& report,
                                                 double time_origin_s,
                                                 const BagExportOptions& options, BagWriter& bag);

}  // namespace uwscan::ros
