#include "scanner/triangulation/light_cone.hpp"

#include <cmath>
#include <numbers>

#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner {
namespace {

// A pose that is not a rotation would turn the cone into a different quadric; catch it here
// rather than intersect the wrong surface.
void CheckRigid(const OptionChecks& check, const Eigen::Isometry3d& T_C_Q) {
  check.Require(T_C_Q.matrix().allFinite(), "T_C_Q", "finite values");
  const Eigen::Matrix3d R = T_C_Q.linear();
  const double orthogonality_error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (orthogonality_error > 1e-9 || R.determinant() < 0.0) {
    check.Fail("T_C_Q", "a rotation (|R^T R - I| <= 1e-9, det R = +1)",
               "|R^T R - I| = " + OptionValueText(orthogonality_error) +
                   ", det R = " + OptionValueText(R.determinant()));
  }
}

}  // namespace

void EllipticCone::Check() const {
  const OptionChecks check("EllipticCone");
  CheckRigid(check, T_C_Q);
  check.Positive("a", a);
  check.Finite("b", b);
  check.Require(beta_min_rad >= 0.0 && beta_min_rad <= std::numbers::pi, "beta_min_rad",
                "in [0, pi] rad", beta_min_rad);
  check.Require(beta_max_rad >= beta_min_rad && beta_max_rad <= std::numbers::pi, "beta_max_rad",
                "in [beta_min_rad, pi] rad", beta_max_rad);
  check.NonNegative("h_min_m", h_min_m, "m");
}

Eigen::Vector3d EllipticCone::Point(double h_m, double beta_rad) const {
  return T_C_Q * Eigen::Vector3d(a * h_m * std::cos(beta_rad), b * h_m * std::sin(beta_rad), h_m);
}

PreparedCone PrepareCone(const EllipticCone& cone) {
  cone.Check();
  PreparedCone prepared;
  // s = diag(1/a, 1, 1) * R_C_Q^T * (x_C - t_C_Q): the x row of R^T scaled by 1/a.
  prepared.S_C = cone.T_C_Q.linear().transpose();
  prepared.S_C.row(0) /= cone.a;
  prepared.s_origin = -(prepared.S_C * cone.T_C_Q.translation());
  prepared.b = cone.b;
  prepared.cos_beta_min = std::cos(cone.beta_min_rad);
  prepared.cos_beta_max = std::cos(cone.beta_max_rad);
  prepared.h_min_m = cone.h_min_m;
  prepared.coefficient_tol = detail::kConeCoefficientTol * (1.0 + cone.b * cone.b);
  prepared.origin_size = prepared.s_origin.lpNorm<1>();
  return prepared;
}

RayHit IntersectRayCone(const Ray& ray_in_C, const EllipticCone& cone) {
  return IntersectRayCone(ray_in_C, PrepareCone(cone));
}

}  // namespace uwscan::scanner
