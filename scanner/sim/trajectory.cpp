#include "scanner/sim/trajectory.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::sim {
namespace {

bool FinitePose(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

// A rotation read from a file may carry rounding; anything further from orthonormal than this
// was not meant as a rotation.
bool Orthonormal(const Eigen::Matrix3d& R) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9 &&
         R.determinant() > 0.0;
}

}  // namespace

double Trajectory::start_s() const {
  assert(!poses.empty());
  return poses.empty() ? 0.0 : poses.front().time_s;
}

double Trajectory::end_s() const {
  assert(!poses.empty());
  return poses.empty() ? 0.0 : poses.back().time_s;
}

Eigen::Isometry3d Trajectory::T_W_V(double time_s) const {
  assert(!poses.empty());
  if (poses.size() == 1 || time_s <= poses.front().time_s) return poses.front().T_W_V;
  if (time_s >= poses.back().time_s) return poses.back().T_W_V;
  // First pose strictly after time_s; the segment is [next - 1, next].
  const auto next =
      std::upper_bound(poses.begin(), poses.end(), time_s,
                       [](double t, const TrajectoryPose& pose) { return t < pose.time_s; });
  const TrajectoryPose& a = *(next - 1);
  const TrajectoryPose& b = *next;
  const double alpha = (time_s - a.time_s) / (b.time_s - a.time_s);
  const Eigen::Quaterniond qa(a.T_W_V.linear());
  const Eigen::Quaterniond qb(b.T_W_V.linear());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = qa.slerp(alpha, qb).toRotationMatrix();  // slerp takes the shorter arc
  T.translation() = (1.0 - alpha) * a.T_W_V.translation() + alpha * b.T_W_V.translation();
  return T;
}

void Trajectory::Check() const {
  const OptionChecks check("Trajectory");
  check.Require(FinitePose(T_V_C) && Orthonormal(T_V_C.linear()), "T_V_C",
                "a finite rigid transform");
  check.Require(!poses.empty(), "poses", "at least one pose", "none");
  for (size_t i = 0; i < poses.size(); ++i) {
    const auto field = [i](const char* member) {
      return "poses[" + std::to_string(i) + "]." + member;
    };
    const double time_s = poses[i].time_s;
    if (!std::isfinite(time_s))
      check.Fail(field("time_s"), "a finite time", OptionValueText(time_s));
    if (!FinitePose(poses[i].T_W_V) || !Orthonormal(poses[i].T_W_V.linear())) {
      check.Fail(field("T_W_V"), "a finite rigid transform");
    }
    if (i > 0 && !(time_s > poses[i - 1].time_s)) {
      check.Fail(field("time_s"),
                 "later than the pose before (" + OptionValueText(poses[i - 1].time_s) + " s)",
                 OptionValueText(time_s) + " s");
    }
  }
}

}  // namespace uwscan::scanner::sim
