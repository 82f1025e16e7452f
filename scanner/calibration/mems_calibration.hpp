#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "scanner/calibration/observations.hpp"
#include "scanner/lasers/projection_functions.hpp"
#include "scanner/optics/refractive_camera.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner::calibration {

struct MemsCalibrationOptions {
  int degree = 5;  // of f1..f6 (seed: fifth order)
  // Depth (camera z) at which the projection plane crosses the zero-volt beam; 0 = the middle
  // of the calibration points' depths. The plane is arbitrary for f1..f6 but the scan pattern
  // is straightest where it lies (see projection_functions.hpp).
  double projection_plane_depth_m = 0.0;
  int min_planes_per_pair = 2;  // planes a voltage pair must be seen on to give a line
  void Check() const;
};

// One voltage pair's beam in water, fitted to its dots on the planes (seed eq. 18).
struct VoltageLine {
  Eigen::Vector2d volts = Eigen::Vector2d::Zero();
  Eigen::Vector3d point_C = Eigen::Vector3d::Zero();       // centroid of its points
  Eigen::Vector3d direction_C = Eigen::Vector3d::UnitZ();  // unit, away from the scanner
  double rms_m = 0.0;                                      // distance of its points to the line
  int points = 0;
};

struct MemsCalibrationResult {
  ProjectionFunctions functions;
  std::array<FitErrorStats, 6> errors;  // percent fitting error of f1..f6 (seed Fig. 8)
  std::vector<VoltageLine> lines;
  double line_rms_m = 0.0;  // over every dot: distance to its voltage pair's line
  int dots = 0;             // dots used
  int skipped_pairs = 0;    // voltage pairs seen on too few planes
};

// Seed 001, Sec. III-C: each dot pixel's camera ray in water (through the calibrated camera
// viewport) meets its plane in a 3-D point q_kl; a line is fitted (SVD) to each voltage pair's
// points; the lines are cut by the projection plane (normal along the zero-volt beam) to give
// p_k and v_k; f1..f6 are fitted by linear least squares on normalised inputs (SVD), and
// their percent fitting errors reported. planes_C[l] is plane l in the camera frame; dots[l]
// are the dots seen on it. Throws uwscan::Error naming the problem: fewer than 2 planes, a
// voltage pair seen twice on one plane, too few lines for the polynomial degree, rays that
// miss their plane.
MemsCalibrationResult CalibrateMemsProjection(const RefractiveCamera& camera,
                                              const std::vector<Plane>& planes_C,
                                              const std::vector<std::vector<DotObservation>>& dots,
                                              const MemsCalibrationOptions& options = {});

}  // namespace uwscan::scanner::calibration
