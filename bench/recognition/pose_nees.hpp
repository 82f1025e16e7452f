#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <span>

#include "perception/recognition/free_directions.hpp"

namespace uwscan::bench {

// How far a pose lies from the truth in units of its own reported covariance: the NEES over the
// directions the covariance pins, divided by their number: 1 on average for a consistent
// covariance. The error is the motion x -> x + w x (x - c) + v taking the truth to the estimate,
// in the object frame, ordered [w (rad), v (m)] as RecognizedObject::covariance is, c = centre_O.
// The motions the answer reports free (`free_S`, in the scan frame of T_S_O: its unconstrained
// slides and turns and its continuous symmetries) are taken out of the error first, as the
// motions they are: the error is split into a sum of them plus a part in the covariance's range
// (the directions with a variance above 1e-12 of the largest), and only that part counts. (A
// pseudo-inverse alone would take out what is orthogonal to the range in [rad, m], which for a
// turn about an axis away from the centre, an elbow's free bend or roll, is not the turn: part of
// a free turn then counted as pinned error.) nullopt when the covariance pins no direction.
std::optional<double> PoseNeesPerPinnedDirection(
    const Eigen::Isometry3d& T_S_O, const Eigen::Isometry3d& T_S_O_true,
    const Eigen::Vector3d& centre_O, const Eigen::Matrix<double, 6, 6>& covariance,
    std::span<const perception::FreeDirection> free_S = {});

}  // namespace uwscan::bench
