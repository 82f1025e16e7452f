#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace uwscan::bench {

// How far a pose lies from the truth in units of its own reported covariance: the NEES over the
// directions the covariance pins (those with a variance above 1e-12 of the largest; a free
// direction carries none), divided by their number: 1 on average for a consistent covariance.
// The error is the motion x -> x + w x (x - c) + v taking the truth to the estimate, in the
// object frame, ordered [w (rad), v (m)] as RecognizedObject::covariance is, c = centre_O.
// nullopt when the covariance pins no direction.
std::optional<double> PoseNeesPerPinnedDirection(const Eigen::Isometry3d& T_S_O,
                                                 const Eigen::Isometry3d& T_S_O_true,
                                                 const Eigen::Vector3d& centre_O,
                                                 const Eigen::Matrix<double, 6, 6>& covariance);

}  // namespace uwscan::bench
