#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "scanner/sim/scene.hpp"

namespace uwscan::scanner::sim {

// Another sensor than uwscan's own: a depth camera (structured light or time of flight) as a
// pinhole range image. Each pixel's ray meets the first surface; its depth (along the optical
// axis) is perturbed by Gaussian noise whose standard deviation grows with the depth squared, as
// measured on such cameras (Khoshelham and Elberink 2012: about 1.4 mm at 1 m and 2.2 cm at 4 m
// for the first Kinect). Rays go straight: no viewport, no water (a camera in a housing that
// corrects for it, or in air).
struct DepthCameraOptions {
  int width_px = 320;                  // pixels across, >= 2
  int height_px = 240;                 // pixels down, >= 2
  double horizontal_fov_rad = 1.0123;  // 58 degrees, in (0, pi)
  double min_range_m = 0.3;            // nearer depths are not measured, > 0
  double max_range_m = 4.0;            // farther ones neither, > min_range_m
  // sigma_z = noise_per_m * z^2, metres for z in metres (so 1/m), >= 0.
  double noise_per_m = 0.0014;
  void Check() const;
};

struct DepthScan {
  std::vector<Eigen::Vector3d> points_C;   // camera frame {C}: x right, y down, z forward
  std::vector<std::int32_t> object_index;  // into the objects scanned, per point
};

// The range image of `objects` from a camera at T_W_C, as points (pixels without a surface in
// range are left out). Pixel (u, v) draws its noise from a hash of `seed` and the pixel, so the
// scan does not depend on the order pixels are computed in. Throws uwscan::Error on invalid options
// or objects the ray caster refuses.
DepthScan ScanWithDepthCamera(const std::vector<SceneObject>& objects,
                              const Eigen::Isometry3d& T_W_C, const DepthCameraOptions& options,
                              std::uint64_t seed);

}  // namespace uwscan::scanner::sim
