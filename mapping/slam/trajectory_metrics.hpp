#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <vector>

#include "mapping/slam/pose_graph.hpp"

namespace uwscan::mapping {

struct TimedPose {
  double time_s = 0.0;
  Eigen::Isometry3d T_W_V = Eigen::Isometry3d::Identity();
};

// Absolute trajectory error: RMS of the position errors, metres, without any alignment (the
// estimate and the truth share the world frame). Same length and order required.
double AbsoluteTrajectoryError(const std::vector<TimedPose>& estimate,
                               const std::vector<TimedPose>& truth);

// Relative pose error per metre travelled: for each pose, the first later one at least
// `segment_m` further along the true path; the translation error of the estimated motion
// between them over the true path length, averaged. std::nullopt when the path is shorter.
std::optional<double> RelativeErrorPerMetre(const std::vector<TimedPose>& estimate,
                                            const std::vector<TimedPose>& truth,
                                            double segment_m = 1.0);

// Normalised estimation error squared of each pose, e^T P^-1 e with e = [rotation vector of
// R_est R_true^T, p_est - p_true] and P its 6x6 covariance (pose_graph.hpp's convention); the
// mean over poses (6 for a consistent estimate).
double MeanNees(const std::vector<TimedPose>& estimate, const std::vector<TimedPose>& truth,
                const std::vector<Matrix6d>& covariances);

// Writes a TUM trajectory ("t tx ty tz qx qy qz qw" per line) atomically (temporary + rename).
void WriteTum(const std::filesystem::path& path, const std::vector<TimedPose>& poses);

}  // namespace uwscan::mapping
