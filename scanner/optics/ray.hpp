#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace uwscan::scanner {

// A half-line: points origin + t * direction for t >= 0. direction is unit length unless a
// function says otherwise.
struct Ray {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();

  Eigen::Vector3d At(double t) const { return origin + t * direction; }
};

// Why a ray did or did not meet a surface. Expected outcomes, reported as values.
enum class HitStatus : std::uint8_t {
  kHit = 0,
  kParallel,        // ray (nearly) parallel to the surface or to the other ray
  kBehind,          // the only intersections lie behind the ray origin
  kOutsideSurface,  // the surface's carrier is hit, but outside the part that is lit
  kNoIntersection,  // the line does not meet the surface at all
  kTotalInternalReflection,
};

const char* ToString(HitStatus status);

// Result of intersecting a ray with a surface: the ray parameter and the point.
struct RayHit {
  HitStatus status = HitStatus::kNoIntersection;
  double t = 0.0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();

  bool ok() const { return status == HitStatus::kHit; }
  static RayHit Miss(HitStatus why) { return RayHit{why, 0.0, Eigen::Vector3d::Zero()}; }
};

}  // namespace uwscan::scanner
