#pragma once

#include <Eigen/Geometry>

#include "scanner/optics/flat_viewport.hpp"
#include "scanner/optics/ray.hpp"

namespace uwscan::scanner {

// The laser fan at one mirror angle, resolved into the camera frame so that many rays can
// be traced cheaply (the ray-ray triangulation evaluates it inside a root search).
// A fan ray is parametrised by s = tan(alpha), alpha its angle from the central ray.
struct LaserFan {
  Eigen::Vector3d origin_C;         // emitter
  Eigen::Vector3d central_dir_C;    // x_L
  Eigen::Vector3d spread_dir_C;     // y_L
  Eigen::Vector3d mirror_normal_C;  // reflecting normal at this angle
  double mirror_offset_m = 0.0;     // mirror surface: mirror_normal_C . x = mirror_offset_m
  FlatViewport viewport;            // the laser viewport (a copy: the fan stands alone)

  // The fan ray after the mirror, starting on the mirror surface.
  RayTrace RayInAir(double fan_tan) const;
  // The same ray after the laser viewport, starting on its outer face.
  RayTrace RayInWater(double fan_tan) const;
};

// The 1-axis galvanometer scanner of seed 000: a laser fan reflected by a rotating mirror and
// refracted through the laser viewport. Parameters follow the seed's model
// [rho_s, delta, T_W_M], T_W_L, with the camera frame {C} as the reference frame.
struct GalvoLaser {
  // Emitter pose. The fan lies in the x-y plane of {L}: rays (cos a, sin a, 0), central ray +x,
  // so z_L is the laser-plane normal, as in the seed's calibration of the laser pose.
  Eigen::Isometry3d T_C_L = Eigen::Isometry3d::Identity();
  // Mirror pose: the galvanometer axis is y_M through the origin of {M}; at mirror angle 0 the
  // reflecting normal is +z_M. Mirror angle = step * mirror_step_rad, a rotation about y_M.
  Eigen::Isometry3d T_C_M = Eigen::Isometry3d::Identity();
  double mirror_step_rad = 0.002;    // rho_s: mirror rotation per command step
  double rotation_distance_m = 0.0;  // delta: reflecting surface offset from the axis
  double aperture_rad = 0.9599;      // full fan angle (55 degrees)
  int step_min = -100;               // mirror command range, inclusive
  int step_max = 100;
  FlatViewport viewport;  // the laser viewport, in {C}

  void Check() const;

  double MirrorAngle(int step) const { return step * mirror_step_rad; }
  double MaxFanTan() const;  // tan(aperture / 2)
  LaserFan FanAt(double mirror_angle_rad) const;
  LaserFan FanAtStep(int step) const { return FanAt(MirrorAngle(step)); }
};

}  // namespace uwscan::scanner
