#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "viewer/scene/scene.hpp"
#include "viewer/scene/tum_trajectory.hpp"

// The map report that `uwscan map --json` writes (issue 10), read for drawing.
namespace uwscan::viewer {

struct PoseCovariance {
  double time_s = 0.0;
  // Of (x, y, z, roll, pitch, yaw); the top-left 3x3 is the position's, square metres.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

struct LoopClosure {
  int from_submap = 0;
  int to_submap = 0;
  bool accepted = false;
  std::string reason;
};

struct MapReport {
  std::string log;                           // the dive log it was made from
  std::optional<std::filesystem::path> map;  // the map cloud, resolved against the report's folder
  std::map<std::string, std::vector<StampedPose>>
      trajectories;  // "slam", "dead_reckoning", "truth"
  std::vector<PoseCovariance> pose_covariance;
  std::vector<LoopClosure> loops;
};

// Reads a map report: {"uwscan_format": 1, "kind": "map_report", "log", "map" (optional, relative
// to the report's folder), "trajectories": {name: [[t tx ty tz qx qy qz qw], ...]},
// "pose_covariance": [[t, 36 numbers row-major], ...], "loops": [{from_submap, to_submap,
// accepted, reason}]}. Throws uwscan::Error naming the file and the field when the JSON does
// not parse, the format or kind differs, or a value has the wrong type, count or is not finite.
MapReport ReadMapReport(const std::filesystem::path& path);

// Whether a JSON file says it is a map report (reads only as far as needed to tell).
bool IsMapReport(const std::filesystem::path& path);

struct MapReportDrawing {
  int ellipsoid_every = 10;  // an uncertainty ellipsoid every this many covariance entries, >= 1
  double sigmas = 3.0;       // ellipsoid size in standard deviations, > 0
  void Check() const;
};

// The report's map cloud (when it names one), its trajectories in fixed colours (SLAM blue, dead
// reckoning orange, truth green, others by index) and position ellipsoids at the SLAM pose
// nearest each drawn covariance's time, added to `scene`.
void AddMapReport(const MapReport& report, const MapReportDrawing& drawing, Scene& scene);

}  // namespace uwscan::viewer
