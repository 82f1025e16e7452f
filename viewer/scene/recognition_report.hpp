#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mapping/reconstruction/reconstruction.hpp"
#include "viewer/scene/scene.hpp"

// The recognition report that `uwscan recognize --json` writes (issue 11), read for drawing.
namespace uwscan::viewer {

struct ReportedObject {
  std::string id;  // "unknown" when no object was verified (then no pose and no grasps)
  double score = 0.0;
  Eigen::Isometry3d T_S_O = Eigen::Isometry3d::Identity();
  std::vector<std::pair<std::string, Eigen::Isometry3d>> grasps_S;  // name, T_S_G
  std::vector<std::size_t> segment;                                  // indices into the scan
  Eigen::Vector3d centroid_S = Eigen::Vector3d::Zero();
  bool recognised() const { return id != "unknown"; }
};

struct RecognitionReport {
  std::filesystem::path scan;      // resolved against the report's folder
  std::filesystem::path database;  // resolved against the report's folder
  std::size_t scan_points = 0;     // rows of the scan file, what the segments index
  std::optional<int> scan_sweep;   // the sweep of a dive log recognised
  std::vector<ReportedObject> objects;
};

// Reads {"uwscan_format": 1, "kind": "recognition_report", "scan", "database", "scan_points",
// optionally "scan_sweep", "objects": [{"id", "segment", "centroid_m", and for a recognised object "score", "T_S_O":
// {"matrix"}, "grasps": [{"name", "matrix"}]}]}. Throws uwscan::Error naming the file and the
// field when the JSON does not parse, the format or kind differs, or a value has the wrong
// type or count, is not finite, a pose is not rigid, or an index is beyond scan_points.
RecognitionReport ReadRecognitionReport(const std::filesystem::path& path);

// Whether a JSON file says it is a recognition report.
bool IsRecognitionReport(const std::filesystem::path& path);

// The scan (sensor frame) with each recognised segment's points carrying its object's index
// (-1 for planes, unsegmented points and unknown segments), each recognised object's model from the database placed at
// its pose with the same index (so colouring by object pairs a segment with its model), a
// label with its id and score in front of it, and its grasp frames. A scan that is a dive log is
// triangulated as `recognize` did (the scanner's default method, whatever `log_options` say;
// their table cache is used). Throws uwscan::Error naming the report when its scan
// or database cannot be read, the scan no longer has the report's point count, or the database
// lacks a recognised object.
void AddRecognitionReport(const RecognitionReport& report, const mapping::ReconstructionOptions& log_options,
                          Scene& scene);

}  // namespace uwscan::viewer
