#include "mapping/slam/map_uncertainty.hpp"

#include <cmath>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {

ExpectedSurfaceError::ExpectedSurfaceError(std::size_t stride) : stride_(stride) {
  if (stride == 0) throw Error("expected surface error: stride must be > 0");
}

void ExpectedSurfaceError::Add(const perception::PointCloud& cloud, const Eigen::Isometry3d& T,
                               const Matrix6d& covariance, std::size_t submap) {
  if (cloud.empty()) return;
  if (!cloud.has_normals())
    throw Error("expected surface error: submap " + std::to_string(submap) + " has no normals");
  for (std::size_t i = 0; i < cloud.size(); i += stride_) {
    const Eigen::Vector3d n_W = T.linear() * cloud.normals[i].cast<double>();
    const Eigen::Vector3d arm_W = T.linear() * cloud.Point(i);  // from the pose's position
    // A turn w moves the point by w x arm; along the normal that is w . (arm x n).
    Eigen::Matrix<double, 6, 1> J;
    J << arm_W.cross(n_W), n_W;
    sum_ += J.dot(covariance * J);
    ++count_;
  }
}

double ExpectedSurfaceError::Rms() const {
  return count_ == 0 ? 0.0 : std::sqrt(sum_ / static_cast<double>(count_));
}

double ExpectedSurfaceErrorRms(const std::vector<const perception::PointCloud*>& clouds_V,
                               const std::vector<Eigen::Isometry3d>& T_W_V,
                               const std::vector<Matrix6d>& covariances, std::size_t stride) {
  if (clouds_V.size() != T_W_V.size() || clouds_V.size() != covariances.size()) {
    throw Error("expected surface error: " + std::to_string(clouds_V.size()) + " clouds, " +
                std::to_string(T_W_V.size()) + " poses and " + std::to_string(covariances.size()) +
                " covariances: expected one of each per submap");
  }
  ExpectedSurfaceError error(stride);
  for (std::size_t s = 0; s < clouds_V.size(); ++s)
    error.Add(*clouds_V[s], T_W_V[s], covariances[s], s);
  return error.Rms();
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
