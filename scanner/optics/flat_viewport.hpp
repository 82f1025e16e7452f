#pragma once

#include <Eigen/Core>
#include <optional>

#include "scanner/optics/ray.hpp"

namespace uwscan::scanner {

// A flat viewport: a glass (or acrylic) slab between the dry housing and the water.
// Expressed in the frame of the device behind it (the camera frame {C} for both viewports of
// a scanner). The inner face is the plane normal . x = distance_m; the outer face is
// thickness_m further along the normal. The normal points out of the housing into the water.
// For a scanner used in air, set n_water = 1.
struct FlatViewport {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, housing -> water
  double distance_m = 0.0;                            // signed offset of the inner face
  double thickness_m = 0.0;
  double n_air = 1.0;  // refractive indices, unitless
  double n_glass = 1.49;
  double n_water = 1.33;

  // Throws uwscan::Error naming the field when a value is not usable.
  void Check() const;

  double OuterOffset() const { return distance_m + thickness_m; }
};

// Result of tracing a ray through a viewport.
struct RayTrace {
  HitStatus status = HitStatus::kNoIntersection;
  Ray ray;  // the ray after the last face, starting on that face
  bool ok() const { return status == HitStatus::kHit; }
};

// Traces a ray from inside the housing (origin on the air side) out into the water. Air to
// glass to water never reflects totally when n_air <= n_glass, n_water; misses are kParallel
// (ray parallel to the faces) or kBehind (the faces are behind the ray).
RayTrace TraceOut(const FlatViewport& viewport, const Ray& ray_in_air);

// Traces a ray from the water (origin on the water side) back into the housing. Beyond the
// critical angle it reports kTotalInternalReflection.
RayTrace TraceIn(const FlatViewport& viewport, const Ray& ray_in_water);

// The direction in air, leaving `center_in_air`, whose refracted path through the viewport
// passes exactly through `point_in_water`. Solved in the plane of refraction (the plane
// through the centre containing the normal and the point) as one unknown, the tangent of the
// angle in air, by Newton's method kept inside a bracket that always contains the root.
// kBehind when the point is not beyond the outer face or the centre not inside the housing;
// kNoIntersection when the centre lies on the inner face and the point is beyond reach.
struct DirectionResult {
  HitStatus status = HitStatus::kNoIntersection;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  int iterations = 0;
  bool ok() const { return status == HitStatus::kHit; }
};
DirectionResult DirectionThroughViewport(const FlatViewport& viewport,
                                         const Eigen::Vector3d& center_in_air,
                                         const Eigen::Vector3d& point_in_water);

}  // namespace uwscan::scanner
