#pragma once

#include <memory>
#include <vector>

#include "scanner/optics/camera_ray_table.hpp"
#include "scanner/triangulation/light_plane.hpp"
#include "scanner/triangulation/surface_triangulators.hpp"
#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::scanner {

// Ray-plane triangulation against a fixed list of light planes, one per scan line: the MEMS
// scanner of seed 001 (eqs. 15-16), whose lines are designed to be planes in water. The
// camera ray comes from the refractive camera's table (the seed's eq. 16 is the pinhole ray;
// here the camera looks through its viewport too). mirror_step is the line index into
// planes_C; outside [0, planes_C.size()) every point is kOutsideSurface.
class PlaneTableTriangulator final : public Triangulator {
 public:
  // Throws uwscan::Error on a missing table, an invalid option, or a plane whose normal is
  // not a finite unit vector or whose offset is not finite.
  PlaneTableTriangulator(std::shared_ptr<const CameraRayTable> rays, std::vector<Plane> planes_C,
                         const TriangulationOptions& options = {});
  TriangulationMethod method() const override { return TriangulationMethod::kRayPlane; }
  void TriangulateFrame(int mirror_step, std::span<const Eigen::Vector2d> peaks_px,
                        std::span<TriangulatedPoint> out) const override;

  const std::vector<Plane>& planes_C() const { return planes_C_; }

 private:
  std::shared_ptr<const CameraRayTable> rays_;
  std::vector<Plane> planes_C_;
  double min_sin2_angle_;
};

}  // namespace uwscan::scanner
