#pragma once

#include <Eigen/Core>
#include <cmath>
#include <span>

#include "scanner/optics/ray.hpp"

namespace uwscan::scanner {

// A plane: the points x with normal . x = offset_m. normal is unit length; offset_m is then
// the signed distance of the plane from the origin of its frame, in metres.
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset_m = 0.0;
};

// A fitted plane and its orthogonal (point-to-plane) residuals.
struct PlaneFit {
  Plane plane;
  double rms_m = 0.0;      // root mean square point-to-plane distance
  double max_abs_m = 0.0;  // largest point-to-plane distance
};

// Total least squares plane through `points` (metres): the plane through their centroid
// whose normal is the right singular vector of the centred points with the smallest singular
// value, i.e. the plane minimising the sum of squared orthogonal distances. The normal is
// oriented so that offset_m >= 0 (the frame origin lies on its negative side).
// Throws uwscan::Error when there are fewer than 3 points, when a point is not finite, or when
// the points do not span a plane: all coincident, or collinear to within 1e-9 of their extent
// (second singular value <= 1e-9 x the largest).
PlaneFit FitPlane(std::span<const Eigen::Vector3d> points);

// Intersects a ray with a plane. ray.direction need not be unit length: t is then measured in
// units of |direction| (the point is origin + t * direction either way).
// Misses: kParallel when |normal . direction| <= 1e-12 |direction| (including a zero
// direction); kBehind when the plane lies behind the origin (t < 0). An origin on the plane is
// a hit with t = 0. A NaN anywhere in the input never yields a hit: it is reported as a miss.
// Inline because it is on the triangulation hot path: no square root, one division.
inline RayHit IntersectRayPlane(const Ray& ray, const Plane& plane) {
  const double n_dot_d = plane.normal.dot(ray.direction);
  // Compared squared so that no square root is needed; written negated so a NaN misses.
  if (!(n_dot_d * n_dot_d > 1e-24 * ray.direction.squaredNorm())) {
    return RayHit::Miss(HitStatus::kParallel);
  }
  const double t = (plane.offset_m - plane.normal.dot(ray.origin)) / n_dot_d;
  if (!(t >= 0.0)) {
    return RayHit::Miss(HitStatus::kBehind);
  }
  return RayHit{HitStatus::kHit, t, ray.At(t)};
}

}  // namespace uwscan::scanner
