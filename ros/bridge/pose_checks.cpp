#include "ros/bridge/pose_checks.hpp"

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::ros {

Eigen::Isometry3d PoseFromRosValues(double x, double y, double z, double qx, double qy, double qz,
                                    double qw, const std::string& what) {
  const double values[] = {x, y, z, qx, qy, qz, qw};
  for (double v : values) {
    if (!std::isfinite(v)) throw Error(what + ": a pose value is not finite");
  }
  const Eigen::Quaterniond q(qw, qx, qy, qz);
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    throw Error(what + ": orientation is not a unit quaternion (norm " + std::to_string(q.norm()) +
                ")");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

Covariance6d CovarianceFromRosValues(const double* values, const std::string& what) {
  Covariance6d m;
  for (int i = 0; i < 36; ++i) {
    if (!std::isfinite(values[i]))
      throw Error(what + ": covariance value " + std::to_string(i) + " is not finite");
    m(i / 6, i % 6) = values[i];
  }
  return m;
}

}  // namespace uwscan::ros
