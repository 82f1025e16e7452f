#include "mapping/slam/trajectory_metrics.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

void RequireSameLength(const std::vector<TimedPose>& estimate,
                       const std::vector<TimedPose>& truth) {
  if (estimate.size() != truth.size() || estimate.empty()) {
    throw Error("trajectory metrics: expected two non-empty trajectories of the same length, got " +
                std::to_string(estimate.size()) + " and " + std::to_string(truth.size()));
  }
}

}  // namespace

double AbsoluteTrajectoryError(const std::vector<TimedPose>& estimate,
                               const std::vector<TimedPose>& truth) {
  RequireSameLength(estimate, truth);
  double sum = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    sum += (estimate[i].T_W_V.translation() - truth[i].T_W_V.translation()).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(estimate.size()));
}

std::optional<double> RelativeErrorPerMetre(const std::vector<TimedPose>& estimate,
                                            const std::vector<TimedPose>& truth, double segment_m) {
  RequireSameLength(estimate, truth);
  std::vector<double> along(truth.size(), 0.0);  // true path length from the first pose
  for (std::size_t i = 1; i < truth.size(); ++i) {
    along[i] =
        along[i - 1] + (truth[i].T_W_V.translation() - truth[i - 1].T_W_V.translation()).norm();
  }
  double sum = 0.0;
  int count = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    j = std::max(j, i + 1);
    while (j < truth.size() && along[j] - along[i] < segment_m) ++j;
    if (j >= truth.size()) break;
    const Eigen::Isometry3d true_motion = truth[i].T_W_V.inverse() * truth[j].T_W_V;
    const Eigen::Isometry3d estimated_motion = estimate[i].T_W_V.inverse() * estimate[j].T_W_V;
    sum += (true_motion.inverse() * estimated_motion).translation().norm() / (along[j] - along[i]);
    ++count;
  }
  if (count == 0) return std::nullopt;
  return sum / count;
}

double MeanNees(const std::vector<TimedPose>& estimate, const std::vector<TimedPose>& truth,
                const std::vector<Matrix6d>& covariances) {
  RequireSameLength(estimate, truth);
  if (covariances.size() != estimate.size())
    throw Error("trajectory metrics: one covariance per pose expected");
  double sum = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const Eigen::AngleAxisd rotation(estimate[i].T_W_V.linear() *
                                     truth[i].T_W_V.linear().transpose());
    Vector6d e;
    e << rotation.angle() * rotation.axis(),
        estimate[i].T_W_V.translation() - truth[i].T_W_V.translation();
    sum += e.dot(covariances[i].ldlt().solve(e));
  }
  return sum / static_cast<double>(estimate.size());
}

void WriteTum(const std::filesystem::path& path, const std::vector<TimedPose>& poses) {
  std::string text;
  char line[256];
  for (const TimedPose& p : poses) {
    const Eigen::Quaterniond q(p.T_W_V.linear());
    const Eigen::Vector3d& t = p.T_W_V.translation();
    std::snprintf(line, sizeof(line), "%.9f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", p.time_s,
                  t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
    text += line;
  }
  WriteFileAtomically(path, text);
}

}  // namespace uwscan::mapping
