#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "scanner/optics/flat_viewport.hpp"
#include "scanner/optics/ray.hpp"

namespace uwscan::scanner {

// The physical ("true") 2-axis MEMS laser of seed 001, all in the camera frame {C}:
//
//   emitter --> 2-axis mirror --> wide-angle lens --> laser viewport --> water
//
// This is the model the simulator draws rays from and the calibration is judged against. The
// scanner itself never uses it for triangulation: like the seed, it treats the optics as a
// black box fitted by the polynomial projection functions (projection_functions.hpp).
//
// Mirror. {M} has its origin at the pivot, on the reflecting surface; the rest normal is
// +z_M. tilt_rad = (tx, ty) is a gimbal: the outer frame turns by tx about x_M (fixed to the
// housing), the inner plate by ty about the inner axis, which is y_M turned with the outer
// frame. The reflecting normal is therefore
//   n_M = Rx(tx) Ry(ty) z_M = (sin ty, -sin tx cos ty, cos tx cos ty).
// Channel x (volts.x) drives tx, channel y drives ty.
//
// Static response of each axis (seed: linear only for small voltages, severe nonlinearity
// towards the maximum): an odd, smooth, saturating, invertible map
//   tilt(V) = max_tilt_rad * tanh(s V / max_volts) / tanh(s),    s = saturation,
// so tilt(+-max_volts) = +-max_tilt_rad, s -> 0 is linear, and at max_volts the slope has
// fallen to sech^2(s) of its small-signal value. How strong s can be is bounded by the seed's
// fifth-order projection functions: tanh has poles at +-i pi / (2 s) in V / max_volts, and
// the closer they come to the drive range the worse a degree-5 polynomial follows it. With
// the default scanner, s = 0.5 (slope at max_volts 79 %) leaves fitted rays within 0.1 mm of
// the true ones over 0.6-1.5 m (mean 0.01 mm); s = 1.2 (slope 31 %, fitting errors up to
// 0.5 % like the seed's Fig. 8) leaves up to 2.6 mm at 1.5 m (projection_functions_test).
//
// Lens. {Lens} has the lens plane z_Lens = 0 and the optical axis +z_Lens. A ray crossing the
// plane at angle theta from the axis leaves it at lens_gain * theta, same azimuth, from the
// crossing point (seed: "increases the angle of the incoming light ray by a factor of roughly
// 3"). An ideal angle multiplier is all the seed states about its lens; nothing else of the
// lens is modelled.
struct MemsLaser {
  Eigen::Vector3d emitter_origin_C = Eigen::Vector3d::Zero();      // metres
  Eigen::Vector3d emitter_direction_C = Eigen::Vector3d::UnitX();  // unit
  Eigen::Isometry3d T_C_M = Eigen::Isometry3d::Identity();
  double max_volts = 10.0;  // drive range per axis is [-max_volts, max_volts], volts
  Eigen::Vector2d max_tilt_rad{0.0803, 0.0698};  // mechanical tilt at +max_volts, per axis
  Eigen::Vector2d saturation{0.5, 0.5};          // s per axis, unitless, in (0, 5]
  Eigen::Isometry3d T_C_Lens = Eigen::Isometry3d::Identity();
  double lens_gain = 3.0;  // output angle / input angle from the lens axis, unitless
  FlatViewport viewport;   // the laser viewport, in {C}

  // Throws uwscan::Error naming the field when a value is unusable, and when the beam at zero
  // volts or at a corner of the drive range does not reach the water.
  void Check() const;

  // Static mirror response, per axis. TiltFromVolts is defined for any voltage (it saturates);
  // VoltsFromTilt inverts it and is std::nullopt when a tilt lies beyond the drive range
  // (|tilt| > max_tilt_rad on either axis).
  Eigen::Vector2d TiltFromVolts(const Eigen::Vector2d& volts) const;
  std::optional<Eigen::Vector2d> VoltsFromTilt(const Eigen::Vector2d& tilt_rad) const;

  // Reflecting normal of the mirror at a tilt, in {C}.
  Eigen::Vector3d MirrorNormal_C(const Eigen::Vector2d& tilt_rad) const;

  // The beam after the mirror (starting on it), after the lens (starting on the lens plane),
  // and in water (starting on the viewport's outer face). Misses are values: kParallel /
  // kBehind when a surface is not met, kOutsideSurface when the lens would bend the beam to
  // 90 degrees or more from its axis.
  RayTrace RayAfterMirror(const Eigen::Vector2d& tilt_rad) const;
  RayTrace RayAfterLens(const Eigen::Vector2d& tilt_rad) const;
  RayTrace RayInWaterFromTilt(const Eigen::Vector2d& tilt_rad) const;
  RayTrace RayInWater(const Eigen::Vector2d& volts) const {
    return RayInWaterFromTilt(TiltFromVolts(volts));
  }
};

}  // namespace uwscan::scanner
