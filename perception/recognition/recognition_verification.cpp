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
                     Eigen::Vector2d::Constant(1e9), Eigen::Vector2d::Constant(-1e9), {}};
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
    auto [it, inserted] = around.nearest_depth.emplace(around.BinOf(a), x.norm());
    if (!inserted) it->second = std::min(it->second, x.norm());
  }
  return around;
}

double MissingShare(const ObjectModel& o, const Eigen::Isometry3d& T_S_O, const SceneAround& scene,
                    double radius_m) {
  std::map<Bin, double> model_depth;
  std::vector<std::pair<Eigen::Vector3d, Bin>> facing;
  const Eigen::Matrix3d R = T_S_O.linear();
  for (std::size_t i = 0; i < o.model.size(); ++i) {
    const Eigen::Vector3d x = T_S_O * o.model.Point(i);
    const double depth = x.norm();
    if ((R * o.model.normals[i].cast<double>()).dot(-x / depth) < 0.3) continue;  // grazing or back
    const Eigen::Vector2d a = scene.angles(x);
    if (!scene.InWindow(a)) continue;  // not swept
    const Bin bin = scene.BinOf(a);
    auto [it, inserted] = model_depth.emplace(bin, depth);
    if (!inserted) it->second = std::min(it->second, depth);
    facing.emplace_back(x, bin);
  }
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  std::size_t expected = 0, missing = 0;
  for (const auto& [x, bin] : facing) {
    const double depth = x.norm();
    if (depth > model_depth[bin] + radius_m) continue;  // hidden by the object itself
    const auto in_front = scene.nearest_depth.find(bin);
    if (in_front != scene.nearest_depth.end() && in_front->second < depth - radius_m) continue;  // occluded
    if (!scene.Covered(bin)) continue;  // the sweep did not look there
    ++expected;
    scene.index.Query((x - scene.points.origin).cast<float>(), 1, nearest, squared);
    if (nearest.empty() || squared[0] > radius_m * radius_m) ++missing;
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
