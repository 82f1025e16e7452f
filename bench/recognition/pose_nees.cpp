#include "bench/recognition/pose_nees.hpp"

#include <Eigen/Eigenvalues>

namespace uwscan::bench {

std::optional<double> PoseNeesPerPinnedDirection(const Eigen::Isometry3d& T_S_O,
                                                 const Eigen::Isometry3d& T_S_O_true,
                                                 const Eigen::Vector3d& centre_O,
                                                 const Eigen::Matrix<double, 6, 6>& covariance) {
  const Eigen::Isometry3d delta = T_S_O_true.inverse() * T_S_O;
  const Eigen::AngleAxisd turn(delta.linear());
  Eigen::Matrix<double, 6, 1> error;
  error << turn.angle() * turn.axis(), delta * centre_O - centre_O;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(covariance);
  const double largest = eigen.eigenvalues().maxCoeff();
  double nees = 0.0;
  int pinned = 0;
  for (int k = 0; k < 6; ++k) {
    const double variance = eigen.eigenvalues()[k];
    if (!(variance > 1e-12 * largest)) continue;
    const double along = eigen.eigenvectors().col(k).dot(error);
    nees += along * along / variance;
    ++pinned;
  }
  if (pinned == 0) return std::nullopt;
  return nees / pinned;
}

}  // namespace uwscan::bench
