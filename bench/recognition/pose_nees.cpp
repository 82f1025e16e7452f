#include "bench/recognition/pose_nees.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <vector>

namespace uwscan::bench {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// The twists (about centre_O, object frame) of the motions an answer reports free: its
// unconstrained slides and turns, then its continuous symmetries while there is room (at most
// `room`: the fit's own free turn about a symmetry axis is left out of the unconstrained ones, so
// it counts once).
std::vector<Vector6d> FreeTwists(std::span<const perception::FreeDirection> free_S,
                                 const Eigen::Isometry3d& T_S_O, const Eigen::Vector3d& centre_O,
                                 std::size_t room) {
  using perception::FreeKind;
  using perception::FreeMotion;
  const Eigen::Isometry3d T_O_S = T_S_O.inverse();
  std::vector<Vector6d> twists;
  for (const bool symmetry : {false, true}) {
    for (const perception::FreeDirection& f : free_S) {
      // A discrete symmetry is no motion: the error is already taken modulo it.
      if ((f.kind == FreeKind::kSymmetry) != symmetry) continue;
      if (f.kind == FreeKind::kSymmetry && (f.order != 0 || twists.size() >= room)) continue;
      const Eigen::Vector3d axis_O = (T_O_S.linear() * f.axis_S).normalized();
      Vector6d twist;
      if (f.motion == FreeMotion::kTranslation) {
        twist << Eigen::Vector3d::Zero(), axis_O;
      } else {
        twist << axis_O, axis_O.cross(centre_O - T_O_S * f.point_S);
      }
      twists.push_back(twist);
    }
  }
  return twists;
}

}  // namespace

std::optional<double> PoseNeesPerPinnedDirection(
    const Eigen::Isometry3d& T_S_O, const Eigen::Isometry3d& T_S_O_true,
    const Eigen::Vector3d& centre_O, const Eigen::Matrix<double, 6, 6>& covariance,
    std::span<const perception::FreeDirection> free_S) {
  const Eigen::Isometry3d delta = T_S_O_true.inverse() * T_S_O;
  const Eigen::AngleAxisd turn(delta.linear());
  Vector6d error;
  error << turn.angle() * turn.axis(), delta * centre_O - centre_O;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(covariance);
  const double largest = eigen.eigenvalues().maxCoeff();
  std::vector<int> pinned;
  for (int k = 0; k < 6; ++k) {
    if (eigen.eigenvalues()[k] > 1e-12 * largest) pinned.push_back(k);
  }
  if (pinned.empty()) return std::nullopt;
  // error = sum of free twists x a + sum of pinned eigenvectors x b, solved in least squares
  // (exactly when the free motions and the range together span the six directions).
  const std::vector<Vector6d> free = FreeTwists(free_S, T_S_O, centre_O, 6 - pinned.size());
  Eigen::MatrixXd basis(6, static_cast<Eigen::Index>(free.size() + pinned.size()));
  for (std::size_t j = 0; j < free.size(); ++j) basis.col(static_cast<Eigen::Index>(j)) = free[j];
  for (std::size_t j = 0; j < pinned.size(); ++j) {
    basis.col(static_cast<Eigen::Index>(free.size() + j)) = eigen.eigenvectors().col(pinned[j]);
  }
  const Eigen::VectorXd coefficients = basis.colPivHouseholderQr().solve(error);
  double nees = 0.0;
  for (std::size_t j = 0; j < pinned.size(); ++j) {
    const double along = coefficients[static_cast<Eigen::Index>(free.size() + j)];
    nees += along * along / eigen.eigenvalues()[pinned[j]];
  }
  return nees / static_cast<double>(pinned.size());
}

}  // namespace uwscan::bench
