#pragma once

#include <Eigen/Core>
#include <vector>

#include "scanner/calibration/observations.hpp"
#include "scanner/optics/refractive_camera.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner::calibration {

// One laser calibration point p_ijk of seed 000: a stripe peak u_ijk seen on projection plane i
// at mirror step j, lifted to 3-D by intersecting its camera ray with that plane.
struct LaserCalibrationPoint {
  int plane = 0;        // index i of the projection plane (into the planes the points came from)
  int mirror_step = 0;  // galvanometer command j
  Eigen::Vector2d px = Eigen::Vector2d::Zero();   // the stripe peak, pixels
  Eigen::Vector3d p_C = Eigen::Vector3d::Zero();  // the point on the plane, metres, in {C}
};

// Seed 000, "compute calibration points p_ijk intersecting each u_ijk with its projection plane
// pi_p_i": the camera ray of every peak (through the camera viewport, PixelToRayInWater; in
// air give the camera a viewport with n_water = 1) intersected with the plane its stripe was
// projected on. planes_C[i] is the plane of stripes_per_plane[i], in {C}.
// Peaks whose ray misses (no undistortion, parallel to the plane, plane behind the camera)
// are skipped: they are expected outcomes, not errors. Throws uwscan::Error when the two
// lists differ in length or a plane or peak is not finite.
std::vector<LaserCalibrationPoint> LaserCalibrationPoints(
    const RefractiveCamera& camera, const std::vector<Plane>& planes_C,
    const std::vector<std::vector<StripeObservation>>& stripes_per_plane);

}  // namespace uwscan::scanner::calibration
