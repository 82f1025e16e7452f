#pragma once

#include <optional>

#include "mapping/slam/dive_mapping.hpp"

namespace uwscan::mapping {

// A loop closure counts as false when its registered motion, in the directions it measures, is
// further than this from the true one: a wrong association, not an imprecise right one.
inline constexpr double kFalseLoopTranslation_m = 0.05;
inline constexpr double kFalseLoopRotation_rad = 0.035;  // 2 degrees

// The figures of a mapped dive (against the truth where the log has it).
struct MapSummary {
  int loops_accepted = 0;
  int loops_rejected = 0;
  std::optional<int> loops_false;  // accepted loops that are false (truth needed)
  // Rejected loops whose registration the truth puts within the same tolerance and that failed
  // only the chi-square against the graph's prediction: right loops the test turned away, where
  // the prediction's covariance was too small (truth needed).
  std::optional<int> loops_missed;
  // Consecutive registrations the chi-square against the navigation turned away although the
  // truth puts them within that tolerance and nearer it in position than the navigation's motion,
  // in the directions they measure (DiveMapping::inconsistent_registrations; truth needed).
  std::optional<int> registrations_missed;
  std::optional<double> ate_slam_m, ate_dead_reckoning_m;
  std::optional<double> rpe_slam_per_m, rpe_dead_reckoning_per_m;
  std::optional<double> nees_mean;  // of the SLAM covariances, 6 when consistent
  double real_time_factor = 0.0;    // dive duration / processing time
};

MapSummary Summarise(const DiveMapping& mapping);

// Standard deviations [x, y, z (m), roll, pitch, yaw (rad, about the world's x, y, z)] of a
// [rotation, position] covariance.
Eigen::Matrix<double, 6, 1> PoseStd(const Matrix6d& covariance);

}  // namespace uwscan::mapping
