#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "scanner/calibration/observations.hpp"
#include "scanner/optics/flat_viewport.hpp"
#include "scanner/optics/pinhole_camera.hpp"

namespace uwscan::scanner::calibration {

// Calibration of the camera viewport in water (seed 000, "Camera viewport"; seed 001 Sec. III-B):
// from several underwater views of a calibration pattern, with the intrinsics known from the
// calibration in air, find the flat viewport (normal, distance, thickness, optionally the
// indices) and every pattern pose.

struct ViewportCalibrationOptions {
  // Off by default: with the pattern poses free the thickness is barely observable (see below);
  // it is held at the initial (measured or CAD) value.
  bool refine_thickness = false;
  bool refine_glass_index = false;  // else n_glass stays at the initial value (known material)
  bool refine_water_index = false;  // else n_water stays at the initial value
  int max_iterations = 200;         // Levenberg-Marquardt iterations per solve, > 0 (a
                                    // parameter held on its bound starts one more solve)

  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
};

struct ViewportCalibrationResult {
  FlatViewport viewport;  // the refined viewport (n_air as given)
  // Standard deviations from the covariance of the fit, scaled by the residual variance
  // (sigma^2 = sum of squared residuals / (residual count - parameter count)). normal_std_rad
  // is the larger of the two angular standard deviations of the normal's direction. A held
  // (not refined) parameter has 0; all refined ones have +infinity when Ceres finds the
  // Jacobian rank deficient (or the solve failed). Weakly determined parameters show as large
  // finite values (see the observability note below).
  double normal_std_rad = 0.0;
  double distance_std_m = 0.0;
  double thickness_std_m = 0.0;
  double n_glass_std = 0.0;
  double n_water_std = 0.0;
  // Correlation coefficient of distance and thickness (0 when the thickness is held). Near
  // +-1 the views barely separate them: add views at other distances and tilts.
  double distance_thickness_correlation = 0.0;
  std::vector<Eigen::Isometry3d> T_C_O;  // pattern pose of every view, in view order
  double rms_px = 0.0;                   // root mean square of the corners' 2-D reprojection errors
  double max_px = 0.0;                   // largest 2-D reprojection error of a corner
  std::vector<double> view_rms_px;       // per view, in view order
  int iterations = 0;                    // Levenberg-Marquardt iterations
  bool converged = false;                // a tolerance was met (not the limit, not a failure)
};

// Joint refinement of the viewport and of the pattern poses that minimises the refractive
// reprojection error in pixels, sum over views i and corners j of
// |ProjectPointInWater(T_C_O,i * p_j) - u_i,j|^2, by Levenberg-Marquardt (Ceres) with exact
// derivatives (ProjectThroughViewport). The seed's cost is the distance of the pattern point
// from the camera ray in water; reprojection is chosen instead because the noise is in the
// corners (pixels): its least squares is the maximum-likelihood estimate for isotropic
// Gaussian corner noise, whereas a point-to-ray distance weights each corner by its range.
//
// Starts: the viewport at `initial` (the CAD design), each pattern pose by EstimatePatternPose
// through it. Unknowns: the normal (unit vector on the sphere, 2 degrees of freedom), distance
// and, per options, thickness, n_glass and n_water; n_air stays at initial.n_air. Bounds keep
// distance > 0, thickness >= 0 and the indices in [n_air, 3]; a refined parameter that ends on
// its bound is held there and the rest solved again (the constrained optimum; its standard
// deviation still says how little the data determine it). Deterministic (single threaded).
//
// Observability. With the pattern poses free, a flat port is paraxially a pinhole whose
// position along the normal any common shift of the poses absorbs; the viewport shows only
// through the non-paraxial shape of the refraction. The normal and one combination of distance
// and thickness are well determined; distance and thickness separately only weakly. Figures
// (the default camera, indices known, 20 views at 0.5-1.5 m tilted up to 35 degrees, 0.2 px
// noise): thickness held, distance std 1.4 mm and normal std 1.0 mrad; thickness refined,
// thickness std ~13 cm, distance std ~2 cm, correlation 0.997, and the fit often ends on
// thickness = 0 (60 views at 0.05 px still leave the thickness std at 2 cm). So hold the
// thickness at its measured value (refine_thickness = false) unless such figures say
// otherwise for the data at hand. n_water is well determined (with the intrinsics known it
// sets the magnification: std 8e-4 on the data above) and may be refined; n_glass is not
// (std ~40 even with the thickness held; it trades off against the distance), so hold it at
// the material's value. A fit in the weakly determined directions may also stop at
// max_iterations (converged = false).
//
// Throws uwscan::Error on invalid options, intrinsics or initial viewport (including
// initial.distance_m <= 0: the camera centre must be inside the housing), fewer than 3 views,
// or a view that EstimatePatternPose refuses (malformed, fewer than 4 corners, non-finite
// corners), the message naming the view.
ViewportCalibrationResult CalibrateCameraViewport(
    const PinholeCamera& intrinsics, const FlatViewport& initial, const PatternSpec& spec,
    const std::vector<PatternObservation>& observations,
    const ViewportCalibrationOptions& options = {});

}  // namespace uwscan::scanner::calibration
