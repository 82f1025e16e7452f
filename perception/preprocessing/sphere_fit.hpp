#pragma once

#include <Eigen/Core>
#include <span>

namespace uwscan::perception {

// A sphere fitted to points and its radial residuals (|p - centre| - radius).
struct SphereFit {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  double rms_m = 0.0;      // root mean square radial residual
  double max_abs_m = 0.0;  // largest radial residual
  int iterations = 0;      // Gauss-Newton steps taken after the algebraic start
};

// Least-squares sphere: the algebraic fit (linear in centre and r^2 - |c|^2, solved by QR on
// coordinates centred and scaled to unit size, so metres or kilometres away from the origin
// alike) refined by Gauss-Newton on the geometric residuals. Throws uwscan::Error with fewer
// than 4 points, a non-finite point, or points that do not determine a sphere (coplanar or
// collinear to numerical precision).
SphereFit FitSphere(std::span<const Eigen::Vector3d> points);

}  // namespace uwscan::perception
