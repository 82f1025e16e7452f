#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "scanner/calibration/laser_points.hpp"
#include "scanner/lasers/galvo_laser.hpp"

namespace uwscan::scanner::calibration {

// Laser calibration of the galvanometer scanner in air (seed 000): the laser pose T_C_L, the
// mirror pose T_C_M, the mirror step rho_s and the rotation distance delta, from calibration
// points p_ijk (stripes of several mirror steps on several projection planes, lifted to 3-D by
// LaserCalibrationPoints).
//
// In air the laser viewport does not bend the fan much but still shifts every ray sideways (a
// flat slab offsets rays by up to ~2 mm here), so the viewport is taken as known (the CAD's)
// and every fan ray is traced through it with air on both sides: whatever the viewport's
// n_water says, it is taken as n_air here. The returned lasers keep the given viewport as it
// is (ready for the underwater model and CalibrateLaserViewport).
//
// What the points cannot tell (they only say where each step's light surface is), and how it
// is fixed:
//  - the turn of {L} about its fan normal z_L only relabels the fan's rays (and moves the
//    aperture's edges): a gauge, held at the start's value;
//  - the mirror origin along the galvanometer axis y_M moves nothing: held at the start's;
//  - turning the mirror by b about its axis and the laser plane by 2b about the same axis
//    leaves every reflected ray unchanged when delta = 0; for delta != 0 the fans change by a
//    few 1e-8 of what the other parameters do (the smallest singular value of the column-scaled
//    Jacobian on the default scanner): far below any noise, so the mirror's zero angle is held
//    at the start's (the CAD's, through the simplified model) and the laser plane's turn is
//    estimated;
//  - the emitter's position within the laser plane (along the central ray x_L and across the
//    fan, y_L): with planar fans any point of the laser plane gives the same reflected planes.
//    The viewport makes it observable only through its slight, direction-dependent shift of
//    the rays (~0.2 mm of fan per metre of emitter along x_L, ~0.5 mm along y_L, here): at 0.1 mm
//    of point noise that is a standard deviation of 8-18 mm, and any model error (a real
//    line generator's rays do not quite meet in one point) would drag it metres away. So it is
//    held, at the point the fan's edge rays meet (the seed's method; see CalibrateGalvoLaser)
//    or at the CAD's. It matters under water, where refraction turns each ray by an amount
//    depending on its direction: 3 mm along x_L moves the in-air fans by 2 um but the in-water
//    fans by 0.14 mm (before the laser viewport calibration absorbs part of it).
// Held components report a standard deviation of 0.

struct GalvoLaserCalibrationOptions {
  bool refine_rotation_distance = true;  // false: delta stays at the start's value
  int max_iterations = 200;              // Levenberg-Marquardt iterations per refinement, > 0

  void Check() const;  // throws uwscan::Error naming the field
};

// One-sigma standard deviations of the refined parameters: the covariance of the
// Levenberg-Marquardt solution scaled by the residual variance (sum r^2 / (points - unknowns)).
// Rotations and positions are small perturbations in the axes of the estimated frames. NaN
// when the covariance could not be computed (rank-deficient data, e.g. a single plane per step).
struct GalvoLaserStdDevs {
  Eigen::Vector3d laser_rotation_rad = Eigen::Vector3d::Zero();  // about x_L, y_L, z_L (held)
  Eigen::Vector3d laser_position_m = Eigen::Vector3d::Zero();    // x_L (held), y_L (held), z_L
  Eigen::Vector2d mirror_axis_rad = Eigen::Vector2d::Zero();     // tilt of y_M about x_M, z_M
  Eigen::Vector2d mirror_position_m = Eigen::Vector2d::Zero();   // axis along x_M, z_M
  double mirror_step_rad = 0.0;
  double rotation_distance_m = 0.0;  // 0 when not refined
};

struct GalvoLaserCalibrationResult {
  GalvoLaser laser;  // the refined full model
  GalvoLaserStdDevs std_devs;
  GalvoLaser simplified;        // the model the refinement started from: the seed's simplified
                                // model (CalibrateGalvoLaser) or the given start (RefineGalvoLaser)
  double residual_rms_m = 0.0;  // distance of each point to its step's light surface (fan)
  double residual_max_m = 0.0;
  int points = 0;                       // calibration points used
  int iterations = 0;                   // Levenberg-Marquardt iterations (all passes)
  bool converged = false;               // Ceres converged (in the last pass), not the limit
  bool emitter_from_edge_rays = false;  // the emitter where the edge rays meet (else the CAD's)
};

// The seed's simplified model (delta = 0): a plane fitted to each mirror step's points; the
// reflected planes' normals turn about the mirror axis by twice the mirror angle, which gives
// the axis direction (normal of the circle the normals lie on), rho_s (half the rate they turn
// at) and, from the planes' offsets, the axis line; the mirror planes pi_s_j through the axis
// reflect the step planes back onto the laser plane pi_l. The mirror's zero angle (which only
// trades against the laser plane's turn about the axis) is taken from `initial`. Laser pose:
// z_L = n_l, y_L along pi_l ^ pi_s_0, x_L = y_L x z_L (the seed's matrix
// [n_l x (n_l x n_s0), n_l x n_s0, n_l] is left-handed; this is it with x_L negated), and the
// emitter at the point of pi_l closest to the fan's edge rays (the stripes' ends traced back
// through the viewport and reflected on the mirror planes) when the stripes reach the aperture's
// edges on two planes or more, else at the CAD emitter moved onto pi_l. Aperture, step range and
// viewport are copied from `initial`, which must also roughly orient the frames (within 90
// degrees). Throws uwscan::Error when the points do not determine the model: fewer than 3 mirror
// steps, a step whose points do not span a plane (stripes on one plane only), a step outside the
// initial's step range.
GalvoLaser SimplifiedGalvoLaser(const std::vector<LaserCalibrationPoint>& points_in_air,
                                const GalvoLaser& initial);

// Refines every parameter of `start` (but those held above, at the start's values) by
// Levenberg-Marquardt, minimising the distance of each point to the exact light surface of its
// step: the perpendicular distance to the nearest fan ray traced through the viewport.
// Throws uwscan::Error on invalid options or start, or fewer points than unknowns.
GalvoLaserCalibrationResult RefineGalvoLaser(
    const std::vector<LaserCalibrationPoint>& points_in_air, const GalvoLaser& start,
    const GalvoLaserCalibrationOptions& options = {});

// SimplifiedGalvoLaser, then RefineGalvoLaser from it. `initial` is the CAD laser: its aperture,
// step range and viewport are taken as given. When the stripes reach the fan's edges (the
// simplified model found the emitter from the edge rays), the edge rays are reflected again on
// the refined mirror (now with delta) and the refinement repeated with the emitter where they
// meet, until it moves less than 1e-11 m (3-5 passes; each shrinks its error ~250 times).
GalvoLaserCalibrationResult CalibrateGalvoLaser(
    const std::vector<LaserCalibrationPoint>& points_in_air, const GalvoLaser& initial,
    const GalvoLaserCalibrationOptions& options = {});

// Distance (metres, >= 0) of p_C from the light surface of `laser` at `mirror_step`: the
// perpendicular distance to the nearest fan ray after the viewport (traced with the viewport's
// own n_water: set it to n_air for fans in air), rays taken as whole lines and not limited to
// the aperture. std::nullopt when the search fails (rays parallel to the mirror or leaving the
// viewport backwards near p_C).
std::optional<double> DistanceToFan(const GalvoLaser& laser, int mirror_step,
                                    const Eigen::Vector3d& p_C);

}  // namespace uwscan::scanner::calibration
