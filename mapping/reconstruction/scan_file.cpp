#include "mapping/reconstruction/scan_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>

#include "mapping/log/dive_log.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/cloud/cloud_scale.hpp"
#include "perception/recognition/recognition_report.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

std::string SweepRange(const std::vector<int>& sweeps) {
  if (sweeps.empty()) return "no sweep";
  if (sweeps.size() == 1) return "only sweep " + std::to_string(sweeps.front());
  return std::to_string(sweeps.size()) + " sweeps, " + std::to_string(sweeps.front()) + " to " +
         std::to_string(sweeps.back());
}

// Refuses a scan no sensor makes, with a hint about the units that would make sense of it. A
// scan whose points all coincide has no size to judge (it holds no object either).
void RequireScanSize(const perception::PointCloud& cloud_m, double metres_per_unit,
                     const std::string& name) {
  const double extent_m = perception::RobustDiagonal(cloud_m);
  if (extent_m == 0.0 || (extent_m >= kSmallestScan_m && extent_m <= kLargestScan_m)) return;
  char size[64];
  std::snprintf(size, sizeof size, "%.4g m", extent_m);
  const bool large = extent_m > kLargestScan_m;
  const std::string hint = large ? (metres_per_unit >= 1.0 ? "is it in millimetres? give --units mm"
                                                           : "check the scan's units (--units)")
                                 : (metres_per_unit < 1.0 ? "is it in metres? give --units m"
                                                          : "check the scan's units (--units)");
  throw Error(name + ": the scan is " + size +
              " across (its points' extent), outside the 5 mm to 100 m a scan can be: " + hint);
}

// A cloud file's points in metres, in the sensor's frame.
ScanFile ReadCloudScan(const std::filesystem::path& path, const ScanFrame& frame) {
  perception::CloudReadStats stats;
  ScanFile scan;
  scan.cloud = perception::ReadCloud(path, &stats);
  scan.rows = std::move(stats.rows);
  scan.rows_in_file = stats.num_in_file;
  scan.metres_per_unit = frame.metres_per_unit;
  if (frame.T_file_sensor) {
    scan.T_file_sensor = *frame.T_file_sensor;
    scan.viewpoint = ViewpointSource::kGiven;
  } else if (!stats.viewpoint_error.empty()) {
    throw Error(stats.viewpoint_error + " (give the sensor's pose with --viewpoint)");
  } else if (stats.T_file_sensor) {
    scan.T_file_sensor = *stats.T_file_sensor;
    scan.viewpoint = ViewpointSource::kFileViewpoint;
  }
  if (frame.metres_per_unit != 1.0) {
    const auto scale = static_cast<float>(frame.metres_per_unit);
    scan.cloud.origin *= frame.metres_per_unit;
    for (Eigen::Vector3f& p : scan.cloud.points) p *= scale;
  }
  if (frame.check_size) RequireScanSize(scan.cloud, frame.metres_per_unit, path.string());
  if (!scan.T_file_sensor.matrix().isIdentity(0.0)) {
    Eigen::Isometry3d T_file_sensor_m = scan.T_file_sensor;
    T_file_sensor_m.translation() *= frame.metres_per_unit;
    scan.cloud = perception::Transformed(scan.cloud, T_file_sensor_m.inverse());
  }
  return scan;
}

}  // namespace

std::string ToString(ViewpointSource source) {
  switch (source) {
    case ViewpointSource::kFileOrigin:
      return "origin";
    case ViewpointSource::kFileViewpoint:
      return "file_viewpoint";
    case ViewpointSource::kGiven:
      return "given";
  }
  return "origin";
}

ScanFile ReadScanFile(const std::filesystem::path& path, ReconstructionOptions options,
                      const ScanFrame& frame) {
  if (!(frame.metres_per_unit > 0.0) || !std::isfinite(frame.metres_per_unit)) {
    throw Error(path.string() + ": the scan's metres per unit must be finite and > 0");
  }
  if (path.extension() != ".db") {
    if (options.sweep) {
      throw Error(path.string() + ": a sweep (" + std::to_string(*options.sweep) +
                  ") is chosen from a dive log, this is a cloud file");
    }
    return ReadCloudScan(path, frame);
  }
  if (frame.metres_per_unit != 1.0 || frame.T_file_sensor) {
    throw Error(path.string() +
                ": a dive log is in metres and in its camera's frame: no unit or "
                "viewpoint is given for it");
  }
  ScanFile scan;
  const DiveLogReader log(path);
  options.use_navigation = true;
  options.relative_to_middle = true;
  const Reconstruction r = Reconstruct(log, options);
  if (!options.sweep && r.sweeps.size() > 1) {
    throw Error(path.string() + ": the dive log holds " + SweepRange(r.sweeps) +
                "; recognition takes one: choose it with --sweep");
  }
  if (options.sweep && r.frames == 0) {
    throw Error(path.string() + ": the dive log has no sweep " + std::to_string(*options.sweep) +
                " (it holds " + SweepRange(r.sweeps) + ")");
  }
  if (r.points.empty()) {
    const std::string what = options.sweep
                                 ? "sweep " + std::to_string(*options.sweep) + " of the dive log"
                                 : std::string("the dive log");
    throw Error(path.string() + ": " + what + " holds no triangulated point");
  }
  scan.cloud = perception::MakeCloud(r.points);
  scan.rows.resize(r.points.size());
  std::iota(scan.rows.begin(), scan.rows.end(), std::size_t{0});
  scan.rows_in_file = r.points.size();
  return scan;
}

ScanFrame ReportedScanFrame(const perception::RecognitionReport& report) {
  ScanFrame frame;
  frame.check_size = false;
  if (report.scan.extension() == ".db") return frame;
  frame.metres_per_unit = report.scan_metres_per_unit;
  frame.T_file_sensor = report.scan_T_file_sensor;
  return frame;
}

}  // namespace uwscan::mapping
