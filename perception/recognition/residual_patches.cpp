#include "perception/recognition/residual_patches.hpp"

#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>

#include "perception/cloud/nearest_grid.hpp"

namespace uwscan::perception {

Eigen::Matrix<double, 6, 6> ResidualPatchSpread(const PointCloud& source,
                                                const Eigen::Isometry3d& T_target_source,
                                                const PointCloud& target, const NearestGrid& grid,
                                                double max_distance_m,
                                                const Eigen::Vector3d& centre_target,
                                                double patch_m) {
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  // Ordered cells, so the sum is the same bits whatever the hashing.
  std::map<std::tuple<long, long, long>, Vector6d> patches;
  const float radius_sq = static_cast<float>(max_distance_m * max_distance_m);
  for (std::size_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d x = T_target_source * source.Point(i);
    const std::int64_t j = grid.Nearest((x - target.origin).cast<float>(), radius_sq);
    if (j < 0) continue;
    const Eigen::Vector3d n = target.normals[static_cast<std::size_t>(j)].cast<double>();
    const double r = n.dot(x - target.Point(static_cast<std::size_t>(j)));
    Vector6d J;
    J << (x - centre_target).cross(n), n;
    const auto key = std::make_tuple(static_cast<long>(std::floor(x.x() / patch_m)),
                                     static_cast<long>(std::floor(x.y() / patch_m)),
                                     static_cast<long>(std::floor(x.z() / patch_m)));
    auto [it, inserted] = patches.try_emplace(key, Vector6d::Zero());
    it->second += J * r;
  }
  Eigen::Matrix<double, 6, 6> spread = Eigen::Matrix<double, 6, 6>::Zero();
  for (const auto& [key, g] : patches) spread += g * g.transpose();
  return spread;
}

}  // namespace uwscan::perception
