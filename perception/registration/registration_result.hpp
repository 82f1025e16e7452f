#pragma once

#include <Eigen/Geometry>

namespace uwscan::perception {

// Outcome of aligning a source cloud onto a target cloud.
struct RegistrationResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  double fitness = 0.0;      // fraction of source points with a target point within range
  double inlier_rmse = 0.0;  // metres, over those inliers
  // Point-to-plane ICP: RMS of n . (p - q) over the inliers, metres (the residual the
  // information is built from); 0 for other methods.
  double inlier_plane_rmse = 0.0;
  int iterations = 0;
  bool converged = false;
  // 6x6 information (inverse covariance up to the noise scale) of the pose, ordered
  // [rotation (rad), translation (m)] in the target frame; its small eigenvalues show the
  // directions the data does not constrain (e.g. sliding along a single plane).
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
};

}  // namespace uwscan::perception
