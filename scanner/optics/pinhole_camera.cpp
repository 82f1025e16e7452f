#include "scanner/optics/pinhole_camera.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>

#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner {
namespace {

// Jacobian of Distort with respect to (x, y).
Eigen::Matrix2d DistortJacobian(const PinholeCamera& c, const Eigen::Vector2d& xy) {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
  const double dradial_dr2 = c.k1 + r2 * (2.0 * c.k2 + 3.0 * r2 * c.k3);
  Eigen::Matrix2d J;
  J(0, 0) = radial + 2.0 * x * x * dradial_dr2 + 2.0 * c.p1 * y + 6.0 * c.p2 * x;
  J(0, 1) = 2.0 * x * y * dradial_dr2 + 2.0 * c.p1 * x + 2.0 * c.p2 * y;
  J(1, 0) = 2.0 * x * y * dradial_dr2 + 2.0 * c.p2 * y + 2.0 * c.p1 * x;
  J(1, 1) = radial + 2.0 * y * y * dradial_dr2 + 2.0 * c.p2 * x + 6.0 * c.p1 * y;
  return J;
}

// True when the radial map r -> r (1 + k1 r^2 + k2 r^4 + k3 r^6) increases strictly on [0, r],
// i.e. a radius r^2 = u lies on the branch of the model through the origin. The derivative is
// g(u) = 1 + 3 k1 u + 5 k2 u^2 + 7 k3 u^3 with g(0) = 1; if g(u) > 0 it can only dip to zero
// inside (0, u) at a minimum, where g'(u) = 3 k1 + 10 k2 u + 21 k3 u^2 vanishes.
bool OnOriginBranch(const PinholeCamera& c, double u) {
  const auto g = [&c](double w) {
    return 1.0 + w * (3.0 * c.k1 + w * (5.0 * c.k2 + w * 7.0 * c.k3));
  };
  if (!(g(u) > 0.0)) return false;
  const double a = 21.0 * c.k3, b = 10.0 * c.k2, k = 3.0 * c.k1;
  std::array<double, 2> critical = {-1.0, -1.0};
  if (a == 0.0) {
    if (b != 0.0) critical[0] = -k / b;
  } else if (const double disc = b * b - 4.0 * a * k; disc >= 0.0) {
    critical[0] = (-b + std::sqrt(disc)) / (2.0 * a);
    critical[1] = (-b - std::sqrt(disc)) / (2.0 * a);
  }
  for (const double w : critical) {
    if (w > 0.0 && w < u && !(g(w) > 0.0)) return false;
  }
  return true;
}

}  // namespace

void PinholeCamera::Check() const {
  const OptionChecks check("PinholeCamera");
  check.GreaterThan("width_px", width_px, 0);
  check.GreaterThan("height_px", height_px, 0);
  check.Positive("fx_px", fx_px);
  check.Positive("fy_px", fy_px);
  check.Finite("cx_px", cx_px);
  check.Finite("cy_px", cy_px);
  check.Require(std::isfinite(k1) && std::isfinite(k2) && std::isfinite(p1) && std::isfinite(p2) &&
                    std::isfinite(k3),
                "distortion", "five finite numbers [k1, k2, p1, p2, k3]");
}

Eigen::Vector2d PinholeCamera::Distort(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

Eigen::Vector2d PinholeCamera::Project(const Eigen::Vector3d& p_C) const {
  const Eigen::Vector2d d = Distort(p_C.head<2>() / p_C.z());
  return {fx_px * d.x() + cx_px, fy_px * d.y() + cy_px};
}

std::optional<Eigen::Vector2d> PinholeCamera::Undistort(const Eigen::Vector2d& uv_px) const {
  const Eigen::Vector2d target((uv_px.x() - cx_px) / fx_px, (uv_px.y() - cy_px) / fy_px);
  Eigen::Vector2d xy = target;
  constexpr int kMaxIterations = 30;
  for (int i = 0; i < kMaxIterations; ++i) {
    const Eigen::Vector2d residual = Distort(xy) - target;
    const Eigen::Matrix2d J = DistortJacobian(*this, xy);
    const double det = J.determinant();
    // A non-positive Jacobian means the model folds over here: no unique undistorted point.
    if (!(det > 1e-12)) return std::nullopt;
    const Eigen::Vector2d step = J.inverse() * residual;
    xy -= step;
    if (step.lpNorm<Eigen::Infinity>() <= 1e-15 * (1.0 + xy.lpNorm<Eigen::Infinity>())) {
      // Newton may converge on an outer branch of the polynomial (beyond the fold): wrong.
      if (!OnOriginBranch(*this, xy.squaredNorm())) return std::nullopt;
      return xy;
    }
  }
  // Newton stalls at the last ulps on some inputs; accept when the residual is at round-off.
  if ((Distort(xy) - target).lpNorm<Eigen::Infinity>() <= 1e-14 * (1.0 + target.norm()) &&
      OnOriginBranch(*this, xy.squaredNorm())) {
    return xy;
  }
  return std::nullopt;
}

std::optional<Eigen::Vector3d> PinholeCamera::BackProject(const Eigen::Vector2d& uv_px) const {
  const std::optional<Eigen::Vector2d> xy = Undistort(uv_px);
  if (!xy) return std::nullopt;
  return Eigen::Vector3d(xy->x(), xy->y(), 1.0).normalized();
}

}  // namespace uwscan::scanner
