#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace uwscan::perception {

// A direction a recognised object's pose leaves undetermined.
// Why a pose leaves a direction free: the object looks the same moved along it (a symmetry), or
// the scan does not show enough of it to pin it (unconstrained).
enum class FreeKind { kSymmetry, kUnconstrained };
enum class FreeMotion { kRotation, kTranslation };
// "symmetry" | "unconstrained", "rotation" | "translation": as recognition reports write them.
std::string ToString(FreeKind kind);
std::string ToString(FreeMotion motion);

struct FreeDirection {
  FreeKind kind = FreeKind::kUnconstrained;
  FreeMotion motion = FreeMotion::kTranslation;
  Eigen::Vector3d axis_S = Eigen::Vector3d::UnitZ();  // unit, scan frame
  Eigen::Vector3d point_S = Eigen::Vector3d::Zero();  // a point on a rotation axis, scan frame
  int order = 0;  // symmetry: 0 continuous, N-fold; unconstrained: 0
};

// What the information of a point-to-plane fit says about the pose it pinned.
struct PoseConstraints {
  // Rigid motions the fit does not pin to within the tolerance, in the object frame: pure
  // translations, then rotations each about its own axis (FreeDirection::point_S and axis_S are
  // in the object frame here).
  std::vector<FreeDirection> free_O;
  // Covariance over [w (rad), v (m)], the object moved by x -> x + w x (x - c) + v, restricted to
  // the directions the fit pins (none along the free ones).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

// Splits the pose of a point-to-plane fit into what it pins and what it leaves free.
//   information: sum of J^T J over the fit's pairs, rows [(x - c) x n, n] (IcpResult's, about c);
//   patch_spread: how the fit's gradient spreads over surface patches (ResidualPatchSpread), or
//   zero; sigma_m: the fit's point-to-plane residual; radius_m: the object's radius, the lever
//   that turns a rotation into metres; tolerance_m: a direction is free when its standard
//   deviation exceeds this (a rotation's at radius_m).
// The covariance is sigma^2 H^-1 (every residual independent) plus H^-1 S H^-1 (residuals
// correlated within patches, independent between them), over the directions the fit pins: the
// first alone is overconfident where misfits span patches (a flange's phase held by its bolt
// heads), the sum at worst twice the variance where residuals are independent.
// The free subspace is split into pure translations (slides) and rotations, each rotation
// reported about its own axis: the axis of the free screw, with any free slide taken out of it,
// and when two rotations are free, the two pure rotations they combine into (a screw system of
// two free rotations holds exactly two zero-pitch screws, e.g. an elbow's bend axis and its
// tube's tangent) rather than an arbitrary mixture of them.
// floor_std_m adds a variance of floor_std_m^2 along every pinned direction (a rotation's at
// radius_m): the error of the model and of the segment's sampling, which no residual shows.
// rest_spread, a covariance over [w (rad), v (m)] like the result's, is where the fit itself comes
// to rest when restarted off the answer (RestartSpread): it adds to the covariance over the pinned
// directions, and a direction of that sum (its own eigenvector) over the tolerance along which the
// restarts alone spread over half the tolerance is free, not pinned by an information the fit's
// flatness belies (a pipe taught from a noisy scan, whose normals tilt a little along its run).
// Throws uwscan::Error when a matrix is not finite and symmetric, a scalar is not positive or the
// floor is negative.
PoseConstraints AnalysePoseConstraints(
    const Eigen::Matrix<double, 6, 6>& information, const Eigen::Matrix<double, 6, 6>& patch_spread,
    const Eigen::Vector3d& centre_O, double sigma_m, double radius_m, double tolerance_m,
    double floor_std_m = 0.0,
    const Eigen::Matrix<double, 6, 6>& rest_spread = Eigen::Matrix<double, 6, 6>::Zero());

}  // namespace uwscan::perception
