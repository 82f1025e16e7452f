#include "perception/registration/cloud_fit.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "perception/cloud/cloud_neighbors.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {

CloudFit FitOnTarget(const PointCloud& source, const PointCloud& target,
                     const Eigen::Isometry3d& T_target_source, double max_distance_m) {
  RequireValidCloud(source, "source", 1);
  RequireValidCloud(target, "target", 1);
  if (!(std::isfinite(max_distance_m) && max_distance_m > 0.0)) {
    throw Error("cloud fit: max_distance_m must be finite and > 0, got " +
                std::to_string(max_distance_m));
  }
  const KnnIndex index(target.points);
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  CloudFit fit;
  double sum_squared = 0.0;
  for (std::size_t i = 0; i < source.size(); ++i) {
    // Relative to the target's origin in double, then float: no precision lost far from zero.
    const Eigen::Vector3d p = T_target_source * source.Point(i) - target.origin;
    index.Query(p.cast<float>(), 1, nearest, squared);
    if (nearest.empty()) continue;
    const double d2 = (p - target.points[nearest[0]].cast<double>()).squaredNorm();
    if (d2 > max_distance_m * max_distance_m) continue;
    sum_squared += d2;
    ++fit.inliers;
  }
  fit.fitness = static_cast<double>(fit.inliers) / static_cast<double>(source.size());
  fit.inlier_rmse_m =
      fit.inliers == 0 ? 0.0 : std::sqrt(sum_squared / static_cast<double>(fit.inliers));
  return fit;
}

}  // namespace uwscan::perception
