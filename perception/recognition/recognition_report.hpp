#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

// The recognition report `uwscan recognize --json` writes (docs/formats.md, "Recognition
// report"), read back: by the viewer to draw it, by `uwscan bag export` to replay it in RViz.
namespace uwscan::perception {

struct ReportedObject {
  std::string id;  // "unknown" when no object was verified (then no pose and no grasps)
  double score = 0.0;
  Eigen::Isometry3d T_S_O = Eigen::Isometry3d::Identity();
  // Over [w (rad), v (m)] in the object frame, as RecognizedObject::covariance; zero when the
  // report has none.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<std::pair<std::string, Eigen::Isometry3d>> grasps_S;  // name, T_S_G
  std::vector<std::size_t> segment;                                 // indices into the scan
  Eigen::Vector3d centroid_S = Eigen::Vector3d::Zero();
  bool recognised() const { return id != "unknown"; }
};

struct RecognitionReport {
  std::filesystem::path scan;      // resolved against the report's folder
  std::filesystem::path database;  // resolved against the report's folder
  std::size_t scan_points = 0;     // rows of the scan file, what the segments index
  std::optional<int> scan_sweep;   // the sweep of a dive log recognised
  // How the scan file was put in the sensor frame: its unit, and the sensor's pose in the file's
  // frame (translation in the file's units; identity for a dive log or a scan from the origin).
  double scan_metres_per_unit = 1.0;
  Eigen::Isometry3d scan_T_file_sensor = Eigen::Isometry3d::Identity();
  std::vector<ReportedObject> objects;
};

// Reads {"uwscan_format": 1, "kind": "recognition_report", "scan", "database", "scan_points",
// optionally "scan_sweep" and "scan_frame": {"metres_per_unit", "T_file_sensor": {"matrix"}},
// "objects": [{"id", "segment", "centroid_m", and for a recognised
// object "score", "T_S_O": {"matrix"}, optionally "covariance" (6 rows of 6), "grasps":
// [{"name", "matrix"}]}]}. Throws uwscan::Error naming the file and the field when the JSON
// does not parse, the format or kind differs, or a value has the wrong type or count, is not
// finite, a pose is not rigid, or an index is beyond scan_points.
RecognitionReport ReadRecognitionReport(const std::filesystem::path& path);

// Whether a JSON file says it is a recognition report.
bool IsRecognitionReport(const std::filesystem::path& path);

}  // namespace uwscan::perception
