#include "mapping/slam/map_uncertainty.hpp"

#include <cmath>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {

double ExpectedSurfaceErrorRms(const std::vector<const perception::PointCloud*>& clouds_V,
                               const std::vector<Eigen::Isometry3d>& T_W_V,
                               const std::vector<Matrix6d>& covariances, std::size_t stride) {
  if (clouds_V.size() != T_W_V.size() || clouds_V.size() != covariances.size()) {
    throw Error("expected surface error: " + std::to_string(clouds_V.size()) + " clouds, " +
                std::to_string(T_W_V.size()) + " poses and " + std::to_string(covariances.size()) +
                " covariances: expected one of each per submap");
  }
  if (stride == 0) throw Error("expected surface error: stride must be > 0");
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t s = 0; s < clouds_V.size(); ++s) {
    const perception::PointCloud& cloud = *clouds_V[s];
    if (cloud.empty()) continue;
    if (!cloud.has_normals())
      throw Error("expected surface error: submap " + std::to_string(s) + " has no normals");
    const Eigen::Isometry3d& T = T_W_V[s];
    for (std::size_t i = 0; i < cloud.size(); i += stride) {
      const Eigen::Vector3d n_W = T.linear() * cloud.normals[i].cast<double>();
      const Eigen::Vector3d arm_W = T.linear() * cloud.Point(i);  // from the pose's position
      // A turn w moves the point by w x arm; along the normal that is w . (arm x n).
      Eigen::Matrix<double, 6, 1> J;
      J << arm_W.cross(n_W), n_W;
      sum += J.dot(covariances[s] * J);
      ++count;
    }
  }
  return count == 0 ? 0.0 : std::sqrt(sum / static_cast<double>(count));
}

double ExpectedPositionErrorRms(const std::vector<Matrix6d>& covariances) {
  if (covariances.empty()) throw Error("expected position error: no pose covariances");
  double sum = 0.0;
  for (std::size_t i = 0; i < covariances.size(); ++i) {
    const double variance = covariances[i].bottomRightCorner<3, 3>().trace();
    if (!(variance >= 0.0 && std::isfinite(variance))) {
      throw Error("expected position error: pose " + std::to_string(i) + " has position variance " +
                  std::to_string(variance) + ", expected finite and >= 0");
    }
    sum += variance;
  }
  return std::sqrt(sum / static_cast<double>(covariances.size()));
}

}  // namespace uwscan::mapping
