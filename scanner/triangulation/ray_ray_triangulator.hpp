#pragma once

#include <vector>

#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/triangulation/surface_triangulators.hpp"
#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::scanner {

// Exact ray-ray triangulation (seed 000): alpha = argmin_alpha d(r_alpha,3, r_u,2). The camera
// ray is undistorted and refracted out through the camera viewport exactly; the laser ray of
// fan parameter s = tan(alpha) is reflected by the mirror and refracted through the laser
// viewport exactly. The root of the signed line-to-line distance in s is bracketed by a
// binary search over rays precomputed per mirror step (or the previous peak's interval), then
// refined by secant steps on exact traces kept inside the bracket (bisection when a step
// would leave it), to |ds| <= 1e-15. The point is the midpoint of the common perpendicular;
// a perpendicular longer than 1e-9 m per metre of range (no convergence) is kNoIntersection.
class RayRayTriangulator final : public Triangulator {
 public:
  // fan_samples: rays per step in the bracketing table (>= 3).
  RayRayTriangulator(const GalvoScannerModel& model, const TriangulationOptions& options = {},
                     int fan_samples = 129);
  TriangulationMethod method() const override { return TriangulationMethod::kRayRay; }
  void TriangulateFrame(int mirror_step, std::span<const Eigen::Vector2d> peaks_px,
                        std::span<TriangulatedPoint> out) const override;

  // The same for one camera ray already in water (used by tests and calibration).
  // bracket_hint: optional in/out index of the table interval that bracketed the previous
  // peak; consecutive peaks of a stripe usually fall in the same interval, which then costs
  // two evaluations instead of a binary search.
  TriangulatedPoint TriangulateRay(int mirror_step, const Ray& camera_ray_in_water,
                                   size_t* bracket_hint = nullptr) const;

 private:
  struct FanNode {
    double s;
    Eigen::Vector3d origin;
    Eigen::Vector3d direction;
  };
  struct StepFan {
    LaserFan fan;
    std::vector<FanNode> nodes;  // only rays that reach the water, increasing s
  };
  const StepFan* FanOf(int step) const;

  GalvoScannerModel model_;
  double min_sin2_angle_;
  std::vector<StepFan> steps_;
};

}  // namespace uwscan::scanner
