#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>

#include "scanner/optics/ray.hpp"

namespace uwscan::scanner {

// The three ways of turning a stripe pixel and a mirror step into a point (seed 000):
//   ray-plane: camera ray (tabulated) against the plane fitted to the light surface;
//   ray-cone:  camera ray (tabulated) against the fitted elliptic cone, closed form;
//   ray-ray:   the exact camera ray against the exact refracted laser fan, solving for the
//              fan ray that meets it (no surface model, no tables beyond a search bracket).
enum class TriangulationMethod { kRayPlane, kRayCone, kRayRay };

const char* ToString(TriangulationMethod method);
// Accepts "plane"/"ray_plane", "cone"/"ray_cone", "ray"/"ray_ray"; std::nullopt otherwise.
std::optional<TriangulationMethod> ParseTriangulationMethod(const std::string& name);

// One triangulated stripe pixel: a point in the camera frame, or why there is none.
struct TriangulatedPoint {
  Eigen::Vector3d p_C = Eigen::Vector3d::Zero();
  HitStatus status = HitStatus::kNoIntersection;
  bool ok() const { return status == HitStatus::kHit; }
};

// Common interface, with a batch entry point over the peaks of one frame: per-frame work
// (looking up the light surface of the step) is done once, then a tight loop over the peaks.
class Triangulator {
 public:
  virtual ~Triangulator() = default;
  virtual TriangulationMethod method() const = 0;

  // peaks_px: stripe pixels (OpenCV convention) of a frame taken at `mirror_step`.
  // out.size() must equal peaks_px.size(). A step outside the laser's range marks every
  // point kOutsideSurface.
  virtual void TriangulateFrame(int mirror_step, std::span<const Eigen::Vector2d> peaks_px,
                                std::span<TriangulatedPoint> out) const = 0;
};

}  // namespace uwscan::scanner
