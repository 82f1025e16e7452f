#include "perception/recognition/recognition_verification.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace uwscan::perception {

SceneAround SceneAroundSegment(const PointCloud& whole_scan, const KnnIndex& index, const PointCloud& segment,
                               double radius_m) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < segment.size(); ++i) centroid += segment.Point(i);
  centroid /= static_cast<double>(segment.size());
  SceneAround around{whole_scan, index, SightAngles(centroid.norm() > 0.0 ? centroid : Eigen::Vector3d::UnitZ()),
                     std::max(radius_m / std::max(centroid.norm(), 1e-3), 1e-4),
                     Eigen::Vector2d::Constant(1e9), Eigen::Vector2d::Constant(-1e9), {}, {}};
  for (std::size_t i = 0; i < segment.size(); ++i) {
    const Eigen::Vector2d a = around.angles(segment.Point(i));
    around.lo = around.lo.cwiseMin(a);
    around.hi = around.hi.cwiseMax(a);
  }
  around.lo.array() -= around.bin_rad;
  around.hi.array() += around.bin_rad;
  for (std::size_t i = 0; i < whole_scan.size(); ++i) {
    const Eigen::Vector3d x = whole_scan.Point(i);
    const Eigen::Vector2d a = around.angles(x);
    if (!around.InWindow(a)) continue;
    const Bin bin = around.BinOf(a);
    auto [it, inserted] = around.nearest_depth.emplace(bin, x.norm());
    if (!inserted) it->second = std::min(it->second, x.norm());
    around.points_in_bin[bin].push_back(static_cast<std::uint32_t>(i));
  }
  return around;
}

bool SceneAround::SeenThrough(const Eigen::Vector3d& x, const Eigen::Vector3d& normal, double lateral_m,
                              double beyond_m) const {
  const Bin bin = BinOf(angles(x));
  const double offset = normal.dot(x);
  for (long du = -1; du <= 1; ++du) {
    for (long dv = -1; dv <= 1; ++dv) {
      const auto cell = points_in_bin.find({bin.first + du, bin.second + dv});
      if (cell == points_in_bin.end()) continue;
      for (const std::uint32_t i : cell->second) {
        const Eigen::Vector3d p = points.Point(i);
        const double range = p.norm();
        const Eigen::Vector3d sight = p / range;
        if ((x - x.dot(sight) * sight).squaredNorm() > lateral_m * lateral_m) continue;
        // Where the line of sight meets the surface's plane at x (the caller's x faces the sensor).
        const double surface = offset / normal.dot(sight);
        if (range > surface + beyond_m) return true;
      }
    }
  }
  return false;
}

double MissingShare(const ObjectModel& o, const Eigen::Isometry3d& T_S_O, const SceneAround& scene,
                    double radius_m) {
  std::map<Bin, double> model_depth;
  struct Facing {
    Eigen::Vector3d x, normal;
    Bin bin;
  };
  std::vector<Facing> facing;
  const Eigen::Matrix3d R = T_S_O.linear();
  for (std::size_t i = 0; i < o.model.size(); ++i) {
    const Eigen::Vector3d x = T_S_O * o.model.Point(i);
    const double depth = x.norm();
    const Eigen::Vector3d normal = R * o.model.normals[i].cast<double>().normalized();
    if (normal.dot(-x / depth) < 0.3) continue;  // grazing or back
    const Eigen::Vector2d a = scene.angles(x);
    if (!scene.InWindow(a)) continue;  // not swept
    const Bin bin = scene.BinOf(a);
    auto [it, inserted] = model_depth.emplace(bin, depth);
    if (!inserted) it->second = std::min(it->second, depth);
    facing.push_back({x, normal, bin});
  }
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  std::size_t expected = 0, missing = 0;
  for (const auto& [x, normal, bin] : facing) {
    const double depth = x.norm();
    if (depth > model_depth[bin] + radius_m) continue;  // hidden by the object itself
    const auto in_front = scene.nearest_depth.find(bin);
    if (in_front != scene.nearest_depth.end() && in_front->second < depth - radius_m) continue;  // occluded
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
  return expected == 0 ? 1.0 : static_cast<double>(missing) / static_cast<double>(expected);
}

double CloseShare(const PointCloud& model, const NearestGrid& model_grid, const PointCloud& segment_O,
                  double distance_m, double reach_m) {
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
  return segment_O.empty() ? 0.0 : static_cast<double>(close) / static_cast<double>(segment_O.size());
}

}  // namespace uwscan::perception
