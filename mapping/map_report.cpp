#include "mapping/map_report.hpp"

#include <algorithm>
#include <cmath>

namespace uwscan::mapping {

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
  for (const LoopClosure& loop : m.loops) {
    if (!loop.accepted) continue;
    const Eigen::Isometry3d truth = m.truth[static_cast<size_t>(loop.from)].T_W_V.inverse() *
                                    m.truth[static_cast<size_t>(loop.to)].T_W_V;
    const Eigen::Isometry3d error = truth.inverse() * loop.T_from_to;
    if (error.translation().norm() > kFalseLoopTranslation_m ||
        Eigen::AngleAxisd(error.linear()).angle() > kFalseLoopRotation_rad) {
      ++false_loops;
    }
  }
  s.loops_false = false_loops;
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
