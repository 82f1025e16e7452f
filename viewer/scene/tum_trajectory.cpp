#include "viewer/scene/tum_trajectory.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include "scanner/common/error.hpp"

namespace uwscan::viewer {

StampedPose PoseFromTum(std::span<const double> v, const std::string& where) {
  if (v.size() != 8) {
    throw Error(where + ": expected 8 numbers (t tx ty tz qx qy qz qw), got " +
                std::to_string(v.size()));
  }
  for (const double x : v) {
    if (!std::isfinite(x)) throw Error(where + ": a number is not finite");
  }
  const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    throw Error(where + ": the quaternion (qx qy qz qw) is not unit length (norm " +
                std::to_string(q.norm()) + ")");
  }
  StampedPose pose;
  pose.time_s = v[0];
  pose.T_W_B.linear() = q.normalized().toRotationMatrix();
  pose.T_W_B.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
  return pose;
}

std::vector<StampedPose> ReadTumTrajectory(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot read");
  std::vector<StampedPose> poses;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    for (char& c : line) {
      if (c == ',') c = ' ';
    }
    std::istringstream fields(line);
    std::vector<double> values;
    std::string token;
    while (fields >> token) {
      if (values.empty() && token[0] == '#') break;
      try {
        std::size_t used = 0;
        values.push_back(std::stod(token, &used));
        if (used != token.size()) throw std::invalid_argument(token);
      } catch (const std::exception&) {
        throw Error(path.string() + ":" + std::to_string(number) + ": '" + token +
                    "' is not a number");
      }
    }
    if (values.empty()) continue;
    poses.push_back(PoseFromTum(values, path.string() + ":" + std::to_string(number)));
  }
  if (poses.empty())
    throw Error(path.string() + ": no pose (expected lines of t tx ty tz qx qy qz qw)");
  return poses;
}

}  // namespace uwscan::viewer
