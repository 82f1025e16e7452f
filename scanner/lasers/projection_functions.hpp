#pragma once

#include <Eigen/Geometry>
#include <array>
#include <span>
#include <vector>

#include "scanner/lasers/mems_laser.hpp"
#include "scanner/lasers/polynomial2d.hpp"
#include "scanner/optics/flat_viewport.hpp"

namespace uwscan::scanner {

// The FoV of the projected beam on the projection plane, seed eqs. 7-10: the extreme p_x at
// (+-V_max_x, 0) and the extreme p_y at (0, +-V_max_y). Metres, in {P}.
struct FovLimits {
  Eigen::Vector2d p_min_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d p_max_m = Eigen::Vector2d::Zero();
};

// The seed's black-box model of the MEMS laser (eqs. 1-6): the beam in water for a voltage
// pair is the line through p (on the projection plane) along v, with
//   p_P = (f1(V), f2(V), 0),   v_P = (f3(V), f4(V), sqrt(1 - f3^2 - f4^2)),
// and the inverse V = (f5(p), f6(p)). {P} is the projection plane's frame: the plane is
// z_P = 0 and +z_P is the beam at zero volts, so v_z > 0 over the whole FoV.
struct ProjectionFunctions {
  Eigen::Isometry3d T_C_P = Eigen::Isometry3d::Identity();
  // The calibrated drive range per axis (volts); it contains 0, where eqs. 7-10 are evaluated.
  Eigen::Vector2d volts_min{-1.0, -1.0};
  Eigen::Vector2d volts_max{1.0, 1.0};
  Polynomial2d f1, f2;  // volts -> p_P.x, p_P.y (metres)
  Polynomial2d f3, f4;  // volts -> v_P.x, v_P.y (unitless)
  Polynomial2d f5, f6;  // p_P (metres) -> volts.x, volts.y

  // Throws uwscan::Error when T_C_P is not rigid or the drive range does not contain 0.
  void Check() const;

  bool InDriveRange(const Eigen::Vector2d& volts, double tolerance_v = 0.0) const;

  Eigen::Vector2d PointAt(const Eigen::Vector2d& volts) const {  // f1, f2
    return Eigen::Vector2d(f1(volts), f2(volts));
  }
  Eigen::Vector2d VoltsAt(const Eigen::Vector2d& p_P) const {  // f5, f6
    return Eigen::Vector2d(f5(p_P), f6(p_P));
  }
  // f3, f4 completed to a unit vector. kNoIntersection when f3^2 + f4^2 >= 1, which only an
  // evaluation far outside the calibrated range can produce.
  RayTrace RayInWater_P(const Eigen::Vector2d& volts) const;
  // The same beam in the camera frame. The origin is its point on the projection plane, which
  // may lie beyond parts of the beam in water: read the result as a line (t of either sign).
  RayTrace RayInWater_C(const Eigen::Vector2d& volts) const;

  FovLimits Fov() const;
};

// Percent fitting error of one function over its data, as the seed's Fig. 8:
// |residual| / (max - min of the fitted target) * 100.
struct FitErrorStats {
  double max_percent = 0.0;
  double mean_percent = 0.0;
  double rms_abs = 0.0;  // root mean square residual, in the target's unit
};

struct ProjectionFunctionFit {
  ProjectionFunctions functions;
  std::array<FitErrorStats, 6> errors;  // f1 .. f6
};

// Calibration data: per voltage pair, the beam's point on the projection plane and its unit
// direction, both in {P}.
struct ProjectionSamples {
  Eigen::Isometry3d T_C_P = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector2d> volts;
  std::vector<Eigen::Vector2d> p_P;  // metres
  std::vector<Eigen::Vector3d> v_P;  // unit, v_P.z > 0
};

// Fits f1..f6 (seed eqs. 19-24) by Polynomial2d::Fit. The drive range is the data's bounding
// box. Throws uwscan::Error on mismatched sizes, a direction that is not unit or points
// backwards (v_P.z <= 0), a target that does not vary, and whatever Polynomial2d::Fit rejects.
ProjectionFunctionFit FitProjectionFunctions(std::span<const Eigen::Vector2d> volts,
                                             std::span<const Eigen::Vector2d> p_P,
                                             std::span<const Eigen::Vector3d> v_P,
                                             const Eigen::Isometry3d& T_C_P, int degree = 5);
inline ProjectionFunctionFit FitProjectionFunctions(const ProjectionSamples& samples,
                                                    int degree = 5) {
  return FitProjectionFunctions(samples.volts, samples.p_P, samples.v_P, samples.T_C_P, degree);
}

// Where the projection plane goes by default: 1.3 m along the zero-volt beam beyond the laser
// viewport, which for the default scanner is about 1.25 m deep in the camera frame, the middle
// of the seed's 1-1.5 m working range. The seed calls the plane arbitrary, and for f1..f6
// it is; for the scan pattern it is not. A line of waypoints with constant p_x is straight on
// this plane only: refraction at the flat viewport gives the beams no common origin, so they
// fan out from a few millimetres of caustic and the surface through a straight line drawn on
// the plane bends away from it in depth. With the plane on the viewport's outer face the
// default scanner's light misses its line planes by 1.1 mm rms at 1.25 m deep; with the plane
// 1.3 m out, by 14 um rms (50 waypoints per line; mems_scan_pattern_test).
inline constexpr double kDefaultProjectionPlaneDistance = 1.3;  // metres

// The projection plane a laser implies: normal (+z_P) along the beam at zero volts, origin
// on that beam `distance_m` beyond the viewport's outer face, x_P along x_C projected onto the
// plane, so scan lines of constant p_x are vertical in the camera image.
Eigen::Isometry3d ProjectionPlaneOf(const MemsLaser& laser, double distance_m);

// Traces the true laser on a grid x grid voltage grid spanning its drive range (grid >= 2)
// and records each beam's crossing of the projection plane. Throws uwscan::Error when a beam
// does not reach the water or crosses the plane backwards.
ProjectionSamples SampleLaserRays(const MemsLaser& laser, int grid, double plane_distance_m);

// The "ideal calibration": f1..f6 fitted on exact rays of the true model on a voltage grid
// (the image-based calibration of the seed's Sec. III-C fits the same functions to measured
// data).
ProjectionFunctionFit SampleProjectionFunctionsFit(
    const MemsLaser& laser, int grid = 41,
    double plane_distance_m = kDefaultProjectionPlaneDistance);
inline ProjectionFunctions SampleProjectionFunctions(
    const MemsLaser& laser, int grid = 41,
    double plane_distance_m = kDefaultProjectionPlaneDistance) {
  return SampleProjectionFunctionsFit(laser, grid, plane_distance_m).functions;
}

}  // namespace uwscan::scanner
