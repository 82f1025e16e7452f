#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mapping/reconstruction/reconstruction.hpp"
#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {
struct RecognitionReport;
}

namespace uwscan::mapping {

// A scan no sensor recognising objects makes: over this across (robust extent), its file is not in
// metres; under kSmallestScan_m, not in millimetres. A range scanner sees a scene tens of metres
// wide at most, an object of the database is at least 5 mm across.
inline constexpr double kLargestScan_m = 100.0;
inline constexpr double kSmallestScan_m = 0.005;

// How a cloud file from another tool becomes the sensor frame recognition works in.
struct ScanFrame {
  double metres_per_unit = 1.0;  // the file's unit: 0.001 for millimetres, > 0
  // The sensor's pose in the file's frame, translation in the file's units. Unset: the file's
  // own (a PCD VIEWPOINT line), else the sensor at the file's origin.
  std::optional<Eigen::Isometry3d> T_file_sensor;
  // Refuse a cloud over kLargestScan_m or under kSmallestScan_m across (off when a report's
  // scan is read again: it was accepted once, as it is).
  bool check_size = true;
};

// Where the sensor pose of a scan came from.
enum class ViewpointSource { kFileOrigin, kFileViewpoint, kGiven };
std::string ToString(ViewpointSource source);  // "origin", "file_viewpoint", "given"

// A scan as recognition takes it, in the sensor's frame and in metres, and where each of its
// points is in the file it came from.
struct ScanFile {
  perception::PointCloud cloud;
  // The row of each point of `cloud` in the file: a cloud file's points with a NaN or infinite
  // coordinate are dropped, so a point's index in `cloud` is not its row there; a log's points
  // are numbered in the order they are triangulated. What a report gives to other tools.
  std::vector<std::size_t> rows;
  std::size_t rows_in_file = 0;
  // The frame used: the sensor's pose in the file's frame (translation in the file's units),
  // where it came from, and the file's unit.
  Eigen::Isometry3d T_file_sensor = Eigen::Isometry3d::Identity();
  ViewpointSource viewpoint = ViewpointSource::kFileOrigin;
  double metres_per_unit = 1.0;
};

// Reads a scan: a cloud file (.ply .pcd .xyz), or one sweep of a dive log triangulated with
// `options` (its use_navigation and relative_to_middle are set here): each frame placed with the
// log's navigation at its own time when it has some, the points in the camera frame at the
// sweep's middle, so a sweep taken while the vehicle moved is not smeared; without navigation
// the frames are taken as seen from a scanner at rest. A log of several sweeps needs
// options.sweep. A cloud file is scaled by frame.metres_per_unit and moved into the sensor's
// frame (frame.T_file_sensor, else the file's VIEWPOINT, else its origin); a log is in metres
// and in its camera's frame already. The same file gives the same points in the same order, so
// indices into a scan (a recognition report's segments) stay valid. Throws uwscan::Error naming the
// file when it cannot be read, a log holds several sweeps and none is chosen, the sweep chosen is
// not in it or holds no triangulated point, a sweep is chosen for a cloud file, a unit or viewpoint
// is given for a log, or the cloud is over kLargestScan_m or under kSmallestScan_m across (with a
// hint about its units).
ScanFile ReadScanFile(const std::filesystem::path& path, ReconstructionOptions options = {},
                      const ScanFrame& frame = {});

// The frame a recognition report's scan was read in, to read the scan again the same way.
ScanFrame ReportedScanFrame(const perception::RecognitionReport& report);

}  // namespace uwscan::mapping
