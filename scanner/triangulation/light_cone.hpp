#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "scanner/optics/ray.hpp"

namespace uwscan::scanner {

// The light surface of a laser plane steered behind a flat viewport: after refraction the
// plane becomes (very nearly) an elliptic cone (seed paper 000, "deformation model"). In its
// own frame {Q} the cone is
//   c(h, beta) = [a h cos(beta), b h sin(beta), h],   h > h_min_m, beta in [beta_min, beta_max]
// with the apex at the origin of {Q} and z_Q the axis; T_C_Q poses it in the camera frame.
// a > 0. b may be negative or zero: the lit sheet is y_Q = b h sin(beta) with sin(beta) >= 0,
// so sign(b) selects the sheet y_Q > 0 or y_Q < 0, and b -> 0 flattens the cone continuously
// into the wedge |x_Q| <= a z_Q of the plane y_Q = 0 (a fan that hardly bends). The other
// sheet (the same cone with beta in (-pi, 0)) and the nappe z_Q < 0 are never lit.
struct EllipticCone {
  Eigen::Isometry3d T_C_Q = Eigen::Isometry3d::Identity();
  double a = 1.0;             // unitless, > 0
  double b = 0.0;             // unitless, any sign
  double beta_min_rad = 0.0;  // lit range, 0 <= min <= max <= pi
  double beta_max_rad = std::numbers::pi;
  double h_min_m = 0.0;  // lit for h > h_min_m >= 0 (never the apex)

  // Throws uwscan::Error naming the field when the cone is not usable (a <= 0, a non-finite
  // value, a beta range outside [0, pi] or reversed, h_min_m < 0, a non-rigid T_C_Q).
  void Check() const;

  // The point c(h, beta) in the camera frame {C}, metres. Defined for any h and beta, lit or
  // not.
  Eigen::Vector3d Point(double h_m, double beta_rad) const;
};

// An EllipticCone in the form its ray intersection wants, computed once per cone so that the
// per-ray work has no trigonometry and no matrix inversion. Coordinates s = (x_Q / a, y_Q,
// z_Q): the x axis is scaled by 1/a so that the cone reads u^2 + (y / b)^2 = z^2.
struct PreparedCone {
  Eigen::Matrix3d S_C = Eigen::Matrix3d::Identity();  // s = S_C * x_C + s_origin
  Eigen::Vector3d s_origin = Eigen::Vector3d::Zero();
  double b = 0.0;
  double cos_beta_min = 1.0;  // the lit range as bounds on cos(beta) = u / h
  double cos_beta_max = -1.0;
  double h_min_m = 0.0;
  double coefficient_tol = 0.0;  // detail::kConeCoefficientTol * (1 + b^2)
  double origin_size = 0.0;      // |s_origin|_1: rounding in s scales with it (metres)
};

// Checks the cone (throws uwscan::Error as EllipticCone::Check) and prepares it.
PreparedCone PrepareCone(const EllipticCone& cone);

namespace detail {

// Size, relative to (1 + b^2) |d|^2 for A and (1 + b^2) |o| |d| for B (|o| plus the cone's
// own offset |s_origin|, which sets the rounding in o), below which a quadratic coefficient is
// rounding noise. They are computed to ~1e-16 of that, so 1e-12 leaves four
// digits of margin (and treats rays within ~1e-12 rad of a generator as parallel to it).
inline constexpr double kConeCoefficientTol = 1e-12;
// A line whose moment about the apex is below this fraction of |o| |d| (|o| as above) passes
// through the apex up to rounding: its only intersection is the apex, where beta is undefined,
// and it is never lit.
inline constexpr double kConeApexTol = 1e-12;

}  // namespace detail

// Intersects a ray in the camera frame with the lit part of the cone, in closed form, and
// returns the nearest lit intersection (smallest t >= 0). ray_in_C.direction need not be unit
// length: t is then in units of |direction|; the point is in {C}, metres.
//
// Method. In s coordinates the line o + t d meets the double cone y^2 = b^2 (z^2 - u^2) where
//   A t^2 + 2 B t + C = 0,  A = d_y^2 - b^2 g2,  B = o_y d_y - b^2 g1,  C = o_y^2 - b^2 g0,
// with z^2 - u^2 along the line = g0 + 2 g1 t + g2 t^2. Its discriminant factors exactly as
//   B^2 - A C = b^2 D,  D = m_x^2 - m_z^2 + b^2 m_y^2,  m = o x d (the line's moment),
// which is computed without the cancellation of the two ~o_y^2 d_y^2 terms of B^2 - A C. That
// cancellation is what makes the textbook form lose half its digits as b -> 0 (both roots
// then sit ~b apart around the plane crossing and sqrt(B^2 - A C) is all rounding noise, even
// with Kahan's fma discriminant, because A, B and C themselves are rounded). Here both roots
// keep full relative precision for any b, so |b| = 1e-9 and b = 0 behave like the plane
// y_Q = 0 to rounding. The roots come from the cancellation-free pair
//   q = -(B + sign(B) |b| sqrt(D)),  t1 = q / A,  t2 = C / q.
// A root is lit when t >= 0, z_Q > h_min_m, y_Q has the sign of b (the lit sheet; no test for
// b = 0) and cos(beta_max) z_Q <= u <= cos(beta_min) z_Q, unless the line passes through the
// apex (to rounding), whose only intersection is the apex itself.
//
// Edges, reported as values, never NaN:
//   kParallel        A = B = 0 to rounding: the line lies on the cone or is parallel to it in
//                    a degenerate way (along a generator through the apex, or in a tangent
//                    plane); for b = 0 a ray parallel to the plane y_Q = 0.
//   kNoIntersection  D < 0 and b != 0: the line misses the cone.
//   kBehind          every root has t < 0.
//   kOutsideSurface  a root ahead of the origin but none lit: wrong sheet, other nappe, beta
//                    out of range, h <= h_min_m, or the apex itself. For b = 0 a crossing of
//                    the plane outside the wedge is this, not kNoIntersection.
// A ray parallel to a generator (A = 0 to rounding) has one root, t = -C / (2 B); the other
// is at infinity and is dropped. A NaN in the input is never a hit.
// Cost: two 3x3 products and ~120 flops in all, one square root, two divisions, no
// allocation, no trigonometry (~55 M rays/s on one 2.6 GHz core with the rays in cache).
inline RayHit IntersectRayCone(const Ray& ray_in_C, const PreparedCone& cone) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d o = cone.S_C * ray_in_C.origin + cone.s_origin;
  const Eigen::Vector3d d = cone.S_C * ray_in_C.direction;
  const double bb = cone.b * cone.b;

  // z^2 - u^2 along the line, factored where it is a difference of squares.
  const double g2 = (d.z() - d.x()) * (d.z() + d.x());
  const double g1 = o.z() * d.z() - o.x() * d.x();
  const double g0 = (o.z() - o.x()) * (o.z() + o.x());
  double qa = d.y() * d.y() - bb * g2;
  const double qb = o.y() * d.y() - bb * g1;
  const double qc = o.y() * o.y() - bb * g0;

  // Rounding in o and d is relative to their size, not to the size of each product (which
  // may be exactly zero, e.g. for an origin on the apex), so the zero tests scale with them.
  const double o_size = std::abs(o.x()) + std::abs(o.y()) + std::abs(o.z()) + cone.origin_size;
  const double d_size = std::abs(d.x()) + std::abs(d.y()) + std::abs(d.z());
  const double tol = cone.coefficient_tol * d_size;
  const bool qa_zero = std::abs(qa) <= tol * d_size;
  if (qa_zero && std::abs(qb) <= tol * o_size) {
    return RayHit::Miss(HitStatus::kParallel);
  }
  qa = qa_zero ? 0.0 : qa;  // then t1 = +-inf, dropped below, and t2 = -C / (2 B)

  const Eigen::Vector3d m = o.cross(d);
  const double disc_over_bb = (m.x() - m.z()) * (m.x() + m.z()) + bb * m.y() * m.y();
  if (!(disc_over_bb >= 0.0) && bb != 0.0) {
    return RayHit::Miss(HitStatus::kNoIntersection);
  }
  const double sqrt_disc = std::abs(cone.b) * std::sqrt(std::max(disc_over_bb, 0.0));
  const double q = -(qb + std::copysign(sqrt_disc, qb));
  const double t1 = q / qa;  // q = 0 only at a double root t = 0: then t1 = 0, t2 = NaN
  const double t2 = qc / q;

  // A line through the apex meets the cone nowhere else (unless it lies on it: kParallel
  // above), and a root anywhere near the apex has z_Q ~ rounding: one test per ray.
  const double apex_tol = detail::kConeApexTol * o_size * d_size;
  const bool through_apex = m.squaredNorm() <= apex_tol * apex_tol;
  const auto lit = [&](double t) {
    const double u = o.x() + t * d.x();
    const double y = o.y() + t * d.y();
    const double z = o.z() + t * d.z();
    return t >= 0.0 && t < kInf && z > cone.h_min_m && y * cone.b >= 0.0 &&
           u >= cone.cos_beta_max * z && u <= cone.cos_beta_min * z;
  };
  if (!through_apex) {
    // The nearer root first: seen from outside the cone it is the lit one in the common case,
    // so the farther root is rarely tested. A NaN t2 (q = 0) compares false and drops out;
    // not std::fmin/fmax, which GCC calls in libm for their NaN rules.
    const double t_near = t2 < t1 ? t2 : t1;
    const double t_far = t2 > t1 ? t2 : t1;
    if (lit(t_near)) {
      return RayHit{HitStatus::kHit, t_near, ray_in_C.At(t_near)};
    }
    if (lit(t_far)) {
      return RayHit{HitStatus::kHit, t_far, ray_in_C.At(t_far)};
    }
  }
  const bool ahead = (t1 >= 0.0 && t1 < kInf) || (t2 >= 0.0 && t2 < kInf);
  return RayHit::Miss(ahead ? HitStatus::kOutsideSurface : HitStatus::kBehind);
}

// Convenience form: prepares the cone (with its checks and two cosines) on every call. Use the
// PreparedCone overload for many rays against one cone.
RayHit IntersectRayCone(const Ray& ray_in_C, const EllipticCone& cone);

}  // namespace uwscan::scanner
