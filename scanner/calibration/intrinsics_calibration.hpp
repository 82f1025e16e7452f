#pragma once

#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "scanner/calibration/observations.hpp"
#include "scanner/optics/pinhole_camera.hpp"

namespace uwscan::scanner::calibration {

// Calibration of the camera in air (seed 000 "Camera calibration", seed 001 Sec. III-A):
// focal lengths, principal point and OpenCV's k1 k2 p1 p2 k3 distortion from views of a
// planar pattern, by OpenCV's calibrateCamera (Zhang's method and Levenberg-Marquardt).

struct IntrinsicsOptions {
  int min_views = 4;  // fewer usable views than this is an error, >= 3
  // Views whose 2-D reprojection rms (pixels) is worse than this are rejected and the
  // calibration redone, > 0.
  double reject_view_rms_px = 1.0;
  bool fix_k3 = false;  // hold k3 at 0 (narrow lenses, where k3 only fits noise)

  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
};

struct ViewResidual {
  std::string image;  // PatternObservation::image
  // 2-D reprojection rms of the view (pixels) under the final calibration (a rejected view
  // posed by PnP with the final intrinsics); NaN for a view too small to pose (fewer than 4
  // corners, or all on one line).
  double rms_px = 0.0;
  bool rejected = false;  // left out of the calibration: unusable, or worse than the limit
};

struct IntrinsicsResult {
  PinholeCamera camera;
  // Standard deviations (OpenCV's, from the Jacobian at the solution, scaled by the residual
  // variance); distortion_std in the order k1 k2 p1 p2 k3 (k3's is 0 when fixed).
  double fx_std = 0.0, fy_std = 0.0, cx_std = 0.0, cy_std = 0.0;
  std::array<double, 5> distortion_std{};
  double rms_px = 0.0;                   // 2-D reprojection rms over the accepted views' corners
  std::vector<ViewResidual> views;       // in view order
  std::vector<Eigen::Isometry3d> T_C_O;  // in view order; identity for rejected views
};

// Calibrates the intrinsics from `observations` of the pattern `spec` in images of
// width_px x height_px. Views with fewer than 4 corners or with all corners on one line are
// unusable. Rejection: after each calibration the worst view, if its rms exceeds
// options.reject_view_rms_px, is rejected and the calibration redone, until every remaining
// view is within the limit. One view at a time, because a grossly wrong view (a mislabelled
// corner) drags the intrinsics and inflates the good views' errors in the same pass.
// Deterministic.
// Throws uwscan::Error on invalid options, pattern or image size, a malformed observation
// (naming it), or when fewer than options.min_views views remain ("N of M views usable,
// need K").
IntrinsicsResult CalibrateIntrinsics(const PatternSpec& spec,
                                     const std::vector<PatternObservation>& observations,
                                     int width_px, int height_px,
                                     const IntrinsicsOptions& options = {});

}  // namespace uwscan::scanner::calibration
