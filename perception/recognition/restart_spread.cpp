#include "perception/recognition/restart_spread.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "perception/registration/rigid_increment.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/parallel_tasks.hpp"
#include "scanner/common/symmetrized.hpp"

namespace uwscan::perception {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// The twist of a motion, as IncrementAbout takes it.
Vector6d TwistOf(const Eigen::Isometry3d& motion, const Eigen::Vector3d& centre) {
  const Eigen::AngleAxisd turn(motion.linear());
  Vector6d twist;
  twist << turn.angle() * turn.axis(), motion * centre - centre;
  return twist;
}

}  // namespace

Matrix6d RestartSpread(const PointCloud& source, const IcpTarget& target,
                       const Eigen::Isometry3d& T_target_source, const IcpOptions& icp,
                       const Matrix6d& covariance, const Eigen::Vector3d& centre_O, double radius_m,
                       double step_m, int threads) {
  if (!(radius_m > 0.0 && std::isfinite(radius_m)))
    throw Error("restart spread: radius_m must be positive");
  if (!(step_m > 0.0 && std::isfinite(step_m)))
    throw Error("restart spread: step_m must be positive");
  if (!covariance.allFinite()) throw Error("restart spread: the covariance must be finite");
  // Rotations in metres at the radius, so that one step moves each direction alike.
  Matrix6d D = Matrix6d::Identity();
  D.topLeftCorner<3, 3>() *= 1.0 / radius_m;
  Matrix6d D_inverse = Matrix6d::Identity();
  D_inverse.topLeftCorner<3, 3>() *= radius_m;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(
      Symmetrized(D_inverse * covariance * D_inverse));
  const double largest = eigen.eigenvalues().maxCoeff();
  std::vector<Vector6d> pinned;  // scaled, unit
  Matrix6d onto_pinned = Matrix6d::Zero();
  for (int k = 0; k < 6; ++k) {
    if (!(eigen.eigenvalues()[k] > 1e-12 * largest)) continue;
    pinned.push_back(eigen.eigenvectors().col(k));
    onto_pinned += eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose();
  }
  if (pinned.empty()) return Matrix6d::Zero();

  IcpOptions one = icp;
  one.threads = 1;
  // Where each restart comes to rest (scaled twists from the answer): one per direction and
  // sign, and last the restart from the answer itself, which the others are measured from (the
  // answer may be where an ICP on other points or with a stall rule stopped).
  std::vector<Vector6d> rest(2 * pinned.size() + 1, Vector6d::Zero());
  RunParallelTasks(std::ssize(rest), threads, [&](std::ptrdiff_t k) {
    const std::size_t task = static_cast<std::size_t>(k);
    Vector6d start = Vector6d::Zero();
    if (task < 2 * pinned.size()) start = (task % 2 == 0 ? step_m : -step_m) * pinned[task / 2];
    const Vector6d twist = D * start;
    const Eigen::Isometry3d T_start =
        IncrementAbout(centre_O, twist.head<3>(), twist.tail<3>()) * T_target_source;
    const RegistrationResult r = AlignIcp(source, target, T_start, one);
    rest[task] = D_inverse * TwistOf(r.T_target_source * T_target_source.inverse(), centre_O);
  });
  Matrix6d spread = Matrix6d::Zero();
  for (std::size_t k = 0; k + 1 < rest.size(); ++k) {
    const Vector6d d = onto_pinned * (rest[k] - rest.back());
    spread += 0.5 * d * d.transpose();
  }
  return D * spread * D;
}

}  // namespace uwscan::perception
