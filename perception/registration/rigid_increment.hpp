#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace uwscan::perception {

// The rigid motion x -> R (x - pivot) + pivot + v, R the rotation by |w| radians about w: the
// small-motion twist x -> x + w x (x - pivot) + v applied exactly (ICP's increments, a covariance's
// directions followed a finite step).
inline Eigen::Isometry3d IncrementAbout(const Eigen::Vector3d& pivot, const Eigen::Vector3d& w,
                                        const Eigen::Vector3d& v) {
  Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
  const double angle = w.norm();
  if (angle > 0.0) increment.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  increment.translation() = pivot + v - increment.linear() * pivot;
  return increment;
}

}  // namespace uwscan::perception
