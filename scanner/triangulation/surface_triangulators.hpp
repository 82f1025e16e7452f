#pragma once

#include <memory>

#include "scanner/optics/camera_ray_table.hpp"
#include "scanner/triangulation/light_surface_table.hpp"
#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::scanner {

// Options shared by the triangulators.
struct TriangulationOptions {
  // Below this angle between the camera ray and the light surface (ray-plane: the plane;
  // ray-cone: the cone's tangent plane at the crossing) or the laser ray (ray-ray) the point is
  // reported kParallel: its depth would be unreliable.
  double min_angle_rad = 0.5 * 3.14159265358979323846 / 180.0;
  void Check() const;
};

// The loop shared by every plane-based triangulator: each peak's camera ray (from the table)
// against one plane; rays within min_sin2_angle of the plane (squared sine of the angle) are
// kParallel, planes behind the camera kBehind, pixels outside the table kNoIntersection.
void TriangulatePeaksOnPlane(const CameraRayTable& rays, const Plane& plane, double min_sin2_angle,
                             std::span<const Eigen::Vector2d> peaks_px,
                             std::span<TriangulatedPoint> out);

// Camera ray (from the table) against the plane fitted to the step's light surface.
class RayPlaneTriangulator final : public Triangulator {
 public:
  RayPlaneTriangulator(std::shared_ptr<const CameraRayTable> rays,
                       std::shared_ptr<const LightSurfaceTable> surfaces,
                       const TriangulationOptions& options = {});
  TriangulationMethod method() const override { return TriangulationMethod::kRayPlane; }
  void TriangulateFrame(int mirror_step, std::span<const Eigen::Vector2d> peaks_px,
                        std::span<TriangulatedPoint> out) const override;

 private:
  std::shared_ptr<const CameraRayTable> rays_;
  std::shared_ptr<const LightSurfaceTable> surfaces_;
  double min_sin2_angle_;
};

// Camera ray (from the table) against the elliptic cone fitted to the step's light surface,
// in closed form; crossings within the minimum angle of the cone are kParallel.
class RayConeTriangulator final : public Triangulator {
 public:
  RayConeTriangulator(std::shared_ptr<const CameraRayTable> rays,
                      std::shared_ptr<const LightSurfaceTable> surfaces,
                      const TriangulationOptions& options = {});
  TriangulationMethod method() const override { return TriangulationMethod::kRayCone; }
  void TriangulateFrame(int mirror_step, std::span<const Eigen::Vector2d> peaks_px,
                        std::span<TriangulatedPoint> out) const override;

 private:
  std::shared_ptr<const CameraRayTable> rays_;
  std::shared_ptr<const LightSurfaceTable> surfaces_;
  double min_sin2_angle_;
};

}  // namespace uwscan::scanner
