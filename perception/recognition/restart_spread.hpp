#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "perception/cloud/point_cloud.hpp"
#include "perception/registration/icp.hpp"

namespace uwscan::perception {

// Where the fit's own ICP lets a pose rest, as a covariance over [w (rad), v (m)] (the object
// moved by x -> x + w x (x - c) + v about centre_O, as PoseConstraints::covariance): the ICP
// restarted from the answer moved by step_m each way along each direction `covariance` pins
// (its eigenvectors with rotations scaled by radius_m, so a rotation moves by step_m at the
// radius), and half the sum of d d^T over their resting places d, each taken from where the
// ICP rests when started at the answer itself and kept to the pinned directions (up to 13 ICPs).
// Why: the point-to-plane information is the curvature of the fit at the answer with its pairs
// held; where the pairs slide into each other as the pose moves (an elbow's torus seen over a
// short arc, a panel's face) the fit is far flatter than that curvature says, and ICP from the
// truth comes to rest at the answer or anywhere between. A direction the fit pins as its
// information says brings every restart back (d near 0, nothing added); a flat one leaves them
// where they start (or beyond, free to slide on), and adds step_m^2 or more.
// `source` and `target` are the fit's (T_target_source the answer, `icp` its options); each
// restart runs on one thread, `threads` of them at once; the result does not depend on it.
// Throws uwscan::Error when a scalar is not positive or the covariance is not finite.
Eigen::Matrix<double, 6, 6> RestartSpread(const PointCloud& source, const IcpTarget& target,
                                          const Eigen::Isometry3d& T_target_source,
                                          const IcpOptions& icp,
                                          const Eigen::Matrix<double, 6, 6>& covariance,
                                          const Eigen::Vector3d& centre_O, double radius_m,
                                          double step_m, int threads);

}  // namespace uwscan::perception
