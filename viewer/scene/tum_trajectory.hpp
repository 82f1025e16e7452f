#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace uwscan::viewer {

// One timestamped pose of a trajectory file.
struct StampedPose {
  double time_s = 0.0;
  Eigen::Isometry3d T_W_B = Eigen::Isometry3d::Identity();  // the body (vehicle or camera) in {W}
};

// The pose of 8 numbers in TUM order: t tx ty tz qx qy qz qw. `where` names the source in
// errors. Throws uwscan::Error when a number is not finite or the quaternion is not unit length
// (within 1e-3: files keep 6 to 9 digits).
StampedPose PoseFromTum(std::span<const double> values, const std::string& where);

// Reads a TUM trajectory: one pose per line, `t tx ty tz qx qy qz qw` separated by spaces (or
// commas), '#' comment lines and blank lines skipped. Throws uwscan::Error naming file:line when
// a line does not hold exactly 8 numbers or fails PoseFromTum, and when the file holds no pose.
std::vector<StampedPose> ReadTumTrajectory(const std::filesystem::path& path);

}  // namespace uwscan::viewer
