#include "apps/cli/pose_option.hpp"

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::app {

Eigen::Isometry3d ParsePoseOption(const std::vector<double>& values, const std::string& option,
                                  bool position_alone) {
  const bool counted = values.size() == 7 || (position_alone && values.size() == 3);
  if (!counted) {
    throw Error(option + ": expected 7 numbers: tx ty tz qx qy qz qw" +
                (position_alone ? std::string(" (or 3: tx ty tz)") : std::string()));
  }
  for (double x : values) {
    if (!std::isfinite(x)) throw Error(option + ": every number must be finite");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
  if (values.size() == 3) return T;
  const Eigen::Quaterniond q(values[6], values[3], values[4], values[5]);
  if (std::abs(q.norm() - 1.0) > 1e-6) throw Error(option + ": the quaternion must be unit length");
  T.linear() = q.normalized().toRotationMatrix();
  return T;
}

}  // namespace uwscan::app
