#include "scanner/triangulation/light_cone.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {
namespace {

[[noreturn]] void ThrowField(const std::string& field, const std::string& expected, double got) {
  std::ostringstream message;
  message << "EllipticCone." << field << ": expected " << expected << ", got " << got;
  throw Error(message.str());
}

// A pose that is not a rotation would turn the cone into a different quadric; catch it here
// rather than intersect the wrong surface.
void CheckRigid(const Eigen::Isometry3d& T_C_Q) {
  if (!T_C_Q.matrix().allFinite()) {
    throw Error("EllipticCone.T_C_Q: expected finite values");
  }
  const Eigen::Matrix3d R = T_C_Q.linear();
  const double orthogonality_error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (orthogonality_error > 1e-9 || R.determinant() < 0.0) {
    ThrowField("T_C_Q", "a rotation (|R^T R - I| <= 1e-9, det R = +1)", orthogonality_error);
  }
}

}  // namespace

void EllipticCone::Check() const {
  CheckRigid(T_C_Q);
  if (!(std::isfinite(a) && a > 0.0)) {
    ThrowField("a", "a finite value > 0", a);
  }
  if (!std::isfinite(b)) {
    ThrowField("b", "a finite value", b);
  }
  if (!(beta_min_rad >= 0.0 && beta_min_rad <= std::numbers::pi)) {
    ThrowField("beta_min_rad", "a value in [0, pi]", beta_min_rad);
  }
  if (!(beta_max_rad >= beta_min_rad && beta_max_rad <= std::numbers::pi)) {
    ThrowField("beta_max_rad", "a value in [beta_min_rad, pi]", beta_max_rad);
  }
  if (!(std::isfinite(h_min_m) && h_min_m >= 0.0)) {
    ThrowField("h_min_m", "a finite value >= 0", h_min_m);
  }
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
