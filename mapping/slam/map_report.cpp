#include "mapping/slam/map_report.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "scanner/common/symmetrized.hpp"

namespace uwscan::mapping {

namespace {

// The part of a loop's error [w, v] along what it measures: along a pipe a loop pins all but
// the slide, where its pose is only the prediction and may be off by the drift.
// Exact when the free direction is a pure translation (a slide, mapper.cpp); a loop without a
// usable information is judged whole.
Eigen::Matrix<double, 6, 1> MeasuredPart(const Eigen::Matrix<double, 6, 1>& error,
                                         const Matrix6d& information) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(Symmetrized(information));
  const double largest = eigen.eigenvalues()(5);
  if (!information.allFinite() || !(largest > 0.0)) return error;
  Eigen::Matrix<double, 6, 1> measured = Eigen::Matrix<double, 6, 1>::Zero();
  for (int k = 0; k < 6; ++k) {
    if (!(eigen.eigenvalues()(k) > 1e-9 * largest)) continue;
    measured += eigen.eigenvectors().col(k).dot(error) * eigen.eigenvectors().col(k);
  }
  return measured;
}

// How far a motion between two submaps is from the true one, in the directions `information`
// measures ([w, v]).
Eigen::Matrix<double, 6, 1> MeasuredError(int from, int to, const Eigen::Isometry3d& T_from_to,
                                          const Matrix6d& information,
                                          const std::vector<TimedPose>& truth) {
  const Eigen::Isometry3d T_true =
      truth[static_cast<size_t>(from)].T_W_V.inverse() * truth[static_cast<size_t>(to)].T_W_V;
  return MeasuredPart(PoseError(T_from_to, T_true), information);
}

bool WithinFalseLoopTolerance(const Eigen::Matrix<double, 6, 1>& error) {
  return error.tail<3>().norm() <= kFalseLoopTranslation_m &&
         error.head<3>().norm() <= kFalseLoopRotation_rad;
}

// A consecutive registration the gate turned away although it was right and nearer the truth in
// position than the navigation's motion that stood in for it. (The false-loop tolerance alone is
// too wide for one step of a few centimetres: a registration 3 cm off is a wrong one there.)
bool IsMissed(const InconsistentRegistration& r, const std::vector<TimedPose>& truth) {
  const auto registered = MeasuredError(r.from, r.to, r.T_from_to, r.information, truth);
  const auto predicted = MeasuredError(r.from, r.to, r.T_predicted, r.information, truth);
  return WithinFalseLoopTolerance(registered) &&
         registered.tail<3>().norm() < predicted.tail<3>().norm();
}

}  // namespace

MapSummary Summarise(const DiveMapping& m) {
  MapSummary s;
  for (const LoopClosure& loop : m.loops) (loop.accepted ? s.loops_accepted : s.loops_rejected)++;
  s.real_time_factor = m.seconds > 0.0 ? m.dive_duration_s / m.seconds : 0.0;
  if (m.truth.empty()) return s;
  s.ate_slam_m = AbsoluteTrajectoryError(m.slam, m.truth);
  s.ate_dead_reckoning_m = AbsoluteTrajectoryError(m.dead_reckoning, m.truth);
  s.rpe_slam_per_m = RelativeErrorPerMetre(m.slam, m.truth);
  s.rpe_dead_reckoning_per_m = RelativeErrorPerMetre(m.dead_reckoning, m.truth);
  if (!m.covariances.empty()) s.nees_mean = MeanNees(m.slam, m.truth, m.covariances);
  int false_loops = 0;
  int missed_loops = 0;
  for (const LoopClosure& loop : m.loops) {
    const bool right = WithinFalseLoopTolerance(
        MeasuredError(loop.from, loop.to, loop.T_from_to, loop.information, m.truth));
    if (loop.accepted && !right) ++false_loops;
    if (!loop.accepted && right && loop.reason.starts_with(kInconsistentLoop)) ++missed_loops;
  }
  s.loops_false = false_loops;
  s.loops_missed = missed_loops;
  s.registrations_missed = static_cast<int>(
      std::count_if(m.inconsistent_registrations.begin(), m.inconsistent_registrations.end(),
                    [&](const InconsistentRegistration& r) { return IsMissed(r, m.truth); }));
  return s;
}

Eigen::Matrix<double, 6, 1> PoseStd(const Matrix6d& covariance) {
  Eigen::Matrix<double, 6, 1> std;
  for (int k = 0; k < 3; ++k) {
    std(k) = std::sqrt(std::max(0.0, covariance(3 + k, 3 + k)));
    std(3 + k) = std::sqrt(std::max(0.0, covariance(k, k)));
  }
  return std;
}

}  // namespace uwscan::mapping
