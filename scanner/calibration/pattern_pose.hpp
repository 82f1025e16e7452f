#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "scanner/calibration/observations.hpp"
#include "scanner/optics/flat_viewport.hpp"
#include "scanner/optics/pinhole_camera.hpp"
#include "scanner/optics/refractive_camera.hpp"

namespace uwscan::scanner::calibration {

// The pose of a calibration pattern seen by a camera behind a flat viewport, and the pieces
// every pattern-based calibration step shares: checked corner correspondences and a refractive
// projection that Ceres can differentiate.

// The corners of one observation paired with their points on the pattern.
struct CornerCorrespondences {
  std::vector<Eigen::Vector3d> points_O;  // metres, in the pattern frame {O}
  std::vector<Eigen::Vector2d> pixels;    // the observed corners, pixels
};

// Checks an observation against its pattern and pairs each corner with its point in {O}.
// Throws uwscan::Error naming the image (or "view <index_for_messages>" when the image name is
// empty) and the corner when the id and pixel counts differ, an id is out of range or repeated,
// or a pixel is not finite.
CornerCorrespondences MatchCorners(const PatternSpec& spec, const PatternObservation& observation,
                                   int index_for_messages = -1);

struct PatternPose {
  Eigen::Isometry3d T_C_O = Eigen::Isometry3d::Identity();
  double rms_px = 0.0;     // root mean square refractive reprojection error of the corners
  int iterations = 0;      // Levenberg-Marquardt iterations of the refinement that was kept
  bool converged = false;  // that refinement met a tolerance (not the iteration limit)
};

// The pose of the pattern in the camera frame from one observation, through the viewport.
// Starts: OpenCV's IPPE planar PnP on the undistorted pinhole rays (ignoring refraction), both
// of its solutions, each also with its depth corrected for refraction to first order (a flat
// port makes things look closer by about n_water: see pattern_pose.cpp). Each start is refined
// by Levenberg-Marquardt on the refractive reprojection error (pixels) over the 6 pose degrees
// of freedom, with exact derivatives; the refinement with the lowest cost is returned. With
// equal indices (a viewport in air) the model is a pinhole and exact corners give the exact
// pose. Deterministic (single threaded).
// Throws uwscan::Error on an invalid camera or pattern, a malformed observation (MatchCorners),
// fewer than 4 corners, corners on one line, corners that cannot be undistorted, or when no
// start puts every corner in front of the viewport.
PatternPose EstimatePatternPose(const RefractiveCamera& camera, const PatternSpec& spec,
                                const PatternObservation& observation);

// ---------------------------------------------------------------------------------------------
// Refractive projection for Ceres' automatic differentiation. T is double or a ceres::Jet; no
// Ceres header is needed here. The value comes from DirectionThroughViewport (the bracketed
// Newton solver of flat_viewport.cpp, run on the values) and is then refined by one Newton step
// carried out in T: because the solver's root makes that step's correction vanish, the step
// contributes exactly the implicit-function derivative of the root with respect to every input
// (point, normal, distance, thickness, indices). Agrees with RefractiveCamera::
// ProjectPointInWater to round-off.
//
// The unknown of the step is s = tan(angle in air) / rho, rho = distance of the point from the
// normal through the camera centre: the air direction is then n + s * radial with no division
// by rho, so the projection stays smooth for points on the axis.

namespace detail {
inline double ValueOf(double x) { return x; }
template <typename Jet>
double ValueOf(const Jet& x) {
  return x.a;  // the scalar part of a ceres::Jet
}
}  // namespace detail

// Viewport of RefractiveCamera in T: `normal` unit (to round-off), the camera centre at the
// origin of {C}. Writes the pixel of p_C and returns true, or returns false when the point is
// not beyond the outer face, the camera centre not inside the housing, or the ray not forward.
template <typename T>
bool ProjectThroughViewport(const PinholeCamera& camera, const T normal[3], const T& distance_m,
                            const T& thickness_m, double n_air, const T& n_glass, const T& n_water,
                            const T p_C[3], T uv_px[2]) {
  using detail::ValueOf;
  using std::sqrt;
  const T depth = normal[0] * p_C[0] + normal[1] * p_C[1] + normal[2] * p_C[2];
  const T radial[3] = {p_C[0] - depth * normal[0], p_C[1] - depth * normal[1],
                       p_C[2] - depth * normal[2]};
  const T rho2 = radial[0] * radial[0] + radial[1] * radial[1] + radial[2] * radial[2];
  const T lengths[3] = {distance_m, thickness_m, depth - distance_m - thickness_m};
  const T ratios[3] = {T(1.0), T(n_air) / n_glass, T(n_air) / n_water};
  if (!(ValueOf(distance_m) > 0.0) || !(ValueOf(lengths[2]) > 0.0)) return false;

  FlatViewport viewport;
  viewport.normal = Eigen::Vector3d(ValueOf(normal[0]), ValueOf(normal[1]), ValueOf(normal[2]));
  viewport.distance_m = ValueOf(distance_m);
  viewport.thickness_m = ValueOf(thickness_m);
  viewport.n_air = n_air;
  viewport.n_glass = ValueOf(n_glass);
  viewport.n_water = ValueOf(n_water);
  const Eigen::Vector3d point(ValueOf(p_C[0]), ValueOf(p_C[1]), ValueOf(p_C[2]));
  const DirectionResult in_air = DirectionThroughViewport(viewport, Eigen::Vector3d::Zero(), point);
  if (!in_air.ok()) return false;
  const double cos_air = in_air.direction.dot(viewport.normal);
  if (!(cos_air > 0.0)) return false;
  const double rho = sqrt(ValueOf(rho2));
  double s0 = 0.0;
  if (rho > 0.0) {
    s0 = (in_air.direction - cos_air * viewport.normal).norm() / (cos_air * rho);
  } else {  // on the axis: the paraxial limit, exact there
    s0 = 1.0 / (ValueOf(lengths[0]) + ValueOf(lengths[1]) * ValueOf(ratios[1]) +
                ValueOf(lengths[2]) * ValueOf(ratios[2]));
  }

  // g(s) = sum_i L_i k_i s / sqrt(1 + (1 - k_i^2) rho^2 s^2) - 1: the radial reach of the
  // path divided by rho, minus one. One Newton step from the solver's root s0.
  T g(-1.0);
  T dg(0.0);
  for (int i = 0; i < 3; ++i) {
    const T w = T(1.0) + (T(1.0) - ratios[i] * ratios[i]) * rho2 * (s0 * s0);
    const T root = sqrt(w);
    g += lengths[i] * ratios[i] * s0 / root;
    dg += lengths[i] * ratios[i] / (w * root);
  }
  const T s = T(s0) - g / dg;
  const T direction[3] = {normal[0] + s * radial[0], normal[1] + s * radial[1],
                          normal[2] + s * radial[2]};
  // As ProjectPointInWater: the unit air direction must point forward (z > 1e-12).
  if (!(ValueOf(direction[2]) > 1e-12 * sqrt(1.0 + s0 * s0 * ValueOf(rho2)))) return false;

  // PinholeCamera::Distort and Project, in T.
  const T x = direction[0] / direction[2];
  const T y = direction[1] / direction[2];
  const T r2 = x * x + y * y;
  const T radial_gain = T(1.0) + r2 * (camera.k1 + r2 * (camera.k2 + r2 * camera.k3));
  const T xd = x * radial_gain + 2.0 * camera.p1 * x * y + camera.p2 * (r2 + 2.0 * x * x);
  const T yd = y * radial_gain + camera.p1 * (r2 + 2.0 * y * y) + 2.0 * camera.p2 * x * y;
  uv_px[0] = camera.fx_px * xd + camera.cx_px;
  uv_px[1] = camera.fy_px * yd + camera.cy_px;
  return true;
}

}  // namespace uwscan::scanner::calibration
