#include "scanner/calibration/laser_points.hpp"

#include <cmath>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {

std::vector<LaserCalibrationPoint> LaserCalibrationPoints(
    const RefractiveCamera& camera, const std::vector<Plane>& planes_C,
    const std::vector<std::vector<StripeObservation>>& stripes_per_plane) {
  camera.Check();
  if (planes_C.size() != stripes_per_plane.size()) {
    throw Error("LaserCalibrationPoints: " + std::to_string(planes_C.size()) + " planes but " +
                std::to_string(stripes_per_plane.size()) +
                " stripe lists (one per plane expected)");
  }
  std::vector<LaserCalibrationPoint> points;
  for (size_t i = 0; i < planes_C.size(); ++i) {
    const Plane& plane = planes_C[i];
    if (!plane.normal.allFinite() || !std::isfinite(plane.offset_m) ||
        std::abs(plane.normal.norm() - 1.0) > 1e-9) {
      throw Error("LaserCalibrationPoints: plane " + std::to_string(i) +
                  " must have a finite unit normal and a finite offset");
    }
    for (const StripeObservation& stripe : stripes_per_plane[i]) {
      for (size_t k = 0; k < stripe.peaks_px.size(); ++k) {
        const Eigen::Vector2d& px = stripe.peaks_px[k];
        if (!px.allFinite()) {
          throw Error("LaserCalibrationPoints: plane " + std::to_string(i) + ", stripe '" +
                      stripe.image + "' (step " + std::to_string(stripe.mirror_step) + "): peak " +
                      std::to_string(k) + " is not finite");
        }
        const RayTrace ray = camera.PixelToRayInWater(px);
        if (!ray.ok()) continue;
        const RayHit hit = IntersectRayPlane(ray.ray, plane);
        if (!hit.ok()) continue;
        points.push_back(
            LaserCalibrationPoint{static_cast<int>(i), stripe.mirror_step, px, hit.point});
      }
    }
  }
  return points;
}

}  // namespace uwscan::scanner::calibration
