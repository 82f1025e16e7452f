#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace uwscan::scanner::sim {

// One timestamped pose of the vehicle frame {V} in the world frame {W} (NED).
struct TrajectoryPose {
  double time_s = 0.0;
  Eigen::Isometry3d T_W_V = Eigen::Isometry3d::Identity();
};

// The vehicle's true path: one pose (static) or timestamped poses in increasing time,
// interpolated linearly in position and by slerp in rotation, held at the ends.
struct Trajectory {
  Eigen::Isometry3d T_V_C = Eigen::Isometry3d::Identity();  // camera (scanner) on the vehicle
  std::vector<TrajectoryPose> poses;                        // >= 1, strictly increasing time_s

  bool is_static() const { return poses.size() <= 1; }
  double start_s() const;
  double end_s() const;
  Eigen::Isometry3d T_W_V(double time_s) const;
  Eigen::Isometry3d T_W_C(double time_s) const { return T_W_V(time_s) * T_V_C; }
  // Throws uwscan::Error when empty, unordered or holding a non-finite pose.
  void Check() const;
};

}  // namespace uwscan::scanner::sim
