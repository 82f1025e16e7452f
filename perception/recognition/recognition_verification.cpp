#include "perception/recognition/recognition_verification.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {

SceneAround::SceneAround(const PointCloud& points_in, const KnnIndex& index_in,
                         const Eigen::Vector3d& forward, double bin_rad_in)
    : points(points_in), index(index_in), angles(forward), bin_rad(bin_rad_in) {}

SceneAround SceneAroundSegment(const PointCloud& whole_scan, const KnnIndex& index,
                               const PointCloud& segment, double radius_m, double margin_m) {
  if (segment.empty()) throw Error("verification: the segment is empty");
  const Eigen::Vector3d centroid = Centroid(segment);
  if (!centroid.allFinite()) throw Error("verification: the segment has a non-finite point");
  const double range = std::max(centroid.norm(), 1e-3);
  SceneAround around(whole_scan, index, centroid.norm() > 0.0 ? centroid : Eigen::Vector3d::UnitZ(),
                     std::max(radius_m / range, 1e-4));
  around.lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  around.hi = -around.lo;
  for (std::size_t i = 0; i < segment.size(); ++i) {
    const Eigen::Vector2d a = around.angles(segment.Point(i));
    around.lo = around.lo.cwiseMin(a);
    around.hi = around.hi.cwiseMax(a);
  }
  // The angles are atan2s, within (-pi, pi]: so is the window.
  const double margin_rad = around.bin_rad + margin_m / range;
  around.lo = (around.lo.array() - margin_rad).cwiseMax(-std::numbers::pi);
  around.hi = (around.hi.array() + margin_rad).cwiseMin(std::numbers::pi);
  // Bins about radius_m wide, but at most kMaxBins of them (a segment near the sensor and a wide
  // margin): wider bins only make the depth buffers coarser.
  constexpr double kMaxBins = 4e6;
  const Eigen::Vector2d extent = around.hi - around.lo;
  around.bin_rad = std::max(around.bin_rad, std::sqrt(extent.x() * extent.y() / kMaxBins));
  around.columns = static_cast<long>(extent.x() / around.bin_rad) + 1;
  around.rows = static_cast<long>(extent.y() / around.bin_rad) + 1;
  const std::size_t bins = static_cast<std::size_t>(around.columns * around.rows);
  around.nearest_depth.assign(bins, std::numeric_limits<double>::infinity());
  // The scan points of each bin, counted, then placed (one array, no allocation per bin).
  std::vector<long> bin_of(whole_scan.size());
  around.bin_start.assign(bins + 1, 0);
  for (std::size_t i = 0; i < whole_scan.size(); ++i) {
    const Eigen::Vector3d x = whole_scan.Point(i);
    bin_of[i] = around.BinOf(around.angles(x));
    if (bin_of[i] < 0) continue;
    const std::size_t b = static_cast<std::size_t>(bin_of[i]);
    around.nearest_depth[b] = std::min(around.nearest_depth[b], x.norm());
    ++around.bin_start[b + 1];
  }
  for (std::size_t b = 0; b < bins; ++b) around.bin_start[b + 1] += around.bin_start[b];
  around.bin_points.resize(around.bin_start[bins]);
  std::vector<std::uint32_t> filled(around.bin_start.begin(), around.bin_start.end() - 1);
  for (std::size_t i = 0; i < whole_scan.size(); ++i) {
    if (bin_of[i] >= 0)
      around.bin_points[filled[static_cast<std::size_t>(bin_of[i])]++] =
          static_cast<std::uint32_t>(i);
  }
  return around;
}

bool SceneAround::SeenThrough(const Eigen::Vector3d& x, const Eigen::Vector3d& normal,
                              double lateral_m, double beyond_m) const {
  const long bin = BinOf(angles(x));
  if (bin < 0) return false;
  const long u0 = bin % columns, v0 = bin / columns;
  const double offset = normal.dot(x);
  for (long v = std::max(v0 - 1, 0L); v <= std::min(v0 + 1, rows - 1); ++v) {
    for (long u = std::max(u0 - 1, 0L); u <= std::min(u0 + 1, columns - 1); ++u) {
      const std::size_t b = static_cast<std::size_t>(v * columns + u);
      for (std::uint32_t k = bin_start[b]; k < bin_start[b + 1]; ++k) {
        const Eigen::Vector3d p = points.Point(bin_points[k]);
        const double range = p.norm();
        const Eigen::Vector3d sight = p / range;
        const double along = x.dot(sight);
        if (along <= 0.0 || (x - along * sight).squaredNorm() > lateral_m * lateral_m) continue;
        // Where the line of sight meets the surface's plane at x (the caller's x faces the sensor).
        const double surface = offset / normal.dot(sight);
        if (range > surface + beyond_m) return true;
      }
    }
  }
  return false;
}

SurfaceEvidence ExpectedSurface(const ObjectModel& o, const Eigen::Isometry3d& T_S_O,
                                const SceneAround& scene, double radius_m) {
  std::vector<double> model_depth(scene.nearest_depth.size(),
                                  std::numeric_limits<double>::infinity());
  struct Facing {
    Eigen::Vector3d x, normal;
    std::size_t bin;
  };
  std::vector<Facing> facing;
  const Eigen::Matrix3d R = T_S_O.linear();
  for (std::size_t i = 0; i < o.model.size(); ++i) {
    const Eigen::Vector3d x = T_S_O * o.model.Point(i);
    const double depth = x.norm();
    const Eigen::Vector3d normal = R * o.model.normals[i].cast<double>().normalized();
    if (normal.dot(-x / depth) < 0.3) continue;  // grazing or back
    const long bin = scene.BinOf(scene.angles(x));
    if (bin < 0) continue;  // out of the window
    const std::size_t b = static_cast<std::size_t>(bin);
    model_depth[b] = std::min(model_depth[b], depth);
    facing.push_back({x, normal, b});
  }
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  SurfaceEvidence evidence;
  std::size_t& expected = evidence.expected;
  std::size_t& missing = evidence.missing;
  for (const auto& [x, normal, bin] : facing) {
    const double depth = x.norm();
    if (depth > model_depth[bin] + radius_m) continue;          // hidden by the object itself
    if (scene.nearest_depth[bin] < depth - radius_m) continue;  // behind something the scan saw
    scene.index.Query((x - scene.points.origin).cast<float>(), 1, nearest, squared);
    if (!nearest.empty() && squared[0] <= radius_m * radius_m) {
      ++expected;  // seen
    } else if (scene.SeenThrough(x, normal, 0.5 * radius_m, 0.5 * radius_m)) {
      ++expected;  // the sensor saw past it: not there
      ++missing;
    }
    // Otherwise no line of sight came near it (between two laser lines, outside the pattern):
    // no evidence either way.
  }
  return evidence;
}

double MissingShare(const ObjectModel& o, const Eigen::Isometry3d& T_S_O, const SceneAround& scene,
                    double radius_m) {
  const SurfaceEvidence e = ExpectedSurface(o, T_S_O, scene, radius_m);
  return e.expected == 0 ? 1.0 : static_cast<double>(e.missing) / static_cast<double>(e.expected);
}

std::vector<SupportPlane> SupportPlanesAround(const PointCloud& scan,
                                              const std::vector<DetectedPlane>& planes,
                                              const Eigen::Vector3d& centre, double radius_m,
                                              std::size_t min_points) {
  std::vector<SupportPlane> around;
  for (const DetectedPlane& plane : planes) {
    std::size_t near = 0;
    for (std::size_t i : plane.inliers)
      near += (scan.Point(i) - centre).squaredNorm() <= radius_m * radius_m ? 1 : 0;
    if (near < min_points) continue;
    // The sensor, at the origin, is at signed distance offset_m: make it positive.
    const double side = plane.offset_m >= 0.0 ? 1.0 : -1.0;
    around.push_back({side * plane.normal, side * plane.offset_m});
  }
  return around;
}

SupportContact SupportContactOf(const ObjectModel& o, const Eigen::Isometry3d& T_S_O,
                                const std::vector<SupportPlane>& planes, double depth_m) {
  SupportContact contact;
  if (planes.empty() || o.model.empty()) return contact;
  std::size_t buried = 0;
  for (std::size_t i = 0; i < o.model.size(); ++i) {
    const Eigen::Vector3d x = T_S_O * o.model.Point(i);
    double lowest = std::numeric_limits<double>::infinity();
    for (const SupportPlane& p : planes) lowest = std::min(lowest, p.normal.dot(x) + p.offset_m);
    contact.clearance_m = std::min(contact.clearance_m, lowest);
    buried += lowest < -depth_m ? 1 : 0;
  }
  contact.buried = static_cast<double>(buried) / static_cast<double>(o.model.size());
  return contact;
}

double CloseShare(const PointCloud& model, const NearestGrid& model_grid,
                  const PointCloud& segment_O, double distance_m, double reach_m) {
  const float reach_sq = static_cast<float>(reach_m * reach_m);
  std::size_t close = 0;
  for (std::size_t i = 0; i < segment_O.size(); ++i) {
    const Eigen::Vector3d x = segment_O.Point(i);
    const std::int64_t j = model_grid.Nearest((x - model.origin).cast<float>(), reach_sq);
    if (j < 0) continue;
    const std::size_t nearest = static_cast<std::size_t>(j);
    const Eigen::Vector3d n = model.normals[nearest].cast<double>().normalized();
    close += std::abs(n.dot(x - model.Point(nearest))) <= distance_m ? 1 : 0;
  }
  return segment_O.empty() ? 0.0
                           : static_cast<double>(close) / static_cast<double>(segment_O.size());
}

}  // namespace uwscan::perception
