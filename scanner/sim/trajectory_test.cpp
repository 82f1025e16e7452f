#include "scanner/sim/trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::sim {
namespace {

Eigen::Isometry3d Pose(const Eigen::Vector3d& t, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).matrix();
  T.translation() = t;
  return T;
}

Trajectory TwoPoses() {
  Trajectory t;
  t.poses = {{1.0, Pose({0, 0, 0}, 0.0)}, {3.0, Pose({2.0, -4.0, 1.0}, 1.0)}};
  return t;
}

TEST(SceneTrajectory, StaticPoseHoldsForever) {
  Trajectory t;
  t.poses = {{0.0, Pose({1, 2, 3}, 0.3)}};
  t.Check();
  EXPECT_TRUE(t.is_static());
  EXPECT_TRUE(t.T_W_V(-5.0).isApprox(t.poses[0].T_W_V));
  EXPECT_TRUE(t.T_W_V(100.0).isApprox(t.poses[0].T_W_V));
}

TEST(SceneTrajectory, LinearPositionSlerpRotation) {
  const Trajectory t = TwoPoses();
  t.Check();
  EXPECT_FALSE(t.is_static());
  EXPECT_EQ(t.start_s(), 1.0);
  EXPECT_EQ(t.end_s(), 3.0);
  const Eigen::Isometry3d mid = t.T_W_V(2.5);
  EXPECT_LT((mid.translation() - Eigen::Vector3d(1.5, -3.0, 0.75)).norm(), 1e-15);
  EXPECT_LT((mid.linear() - Pose({0, 0, 0}, 0.75).linear()).norm(), 1e-15);
  // Held at the ends.
  EXPECT_TRUE(t.T_W_V(0.0).isApprox(t.poses.front().T_W_V, 1e-15));
  EXPECT_TRUE(t.T_W_V(9.0).isApprox(t.poses.back().T_W_V, 1e-15));
  // Exactly at the poses.
  EXPECT_TRUE(t.T_W_V(3.0).isApprox(t.poses.back().T_W_V, 1e-15));
}

TEST(SceneTrajectory, SeveralSegmentsAndTheCamera) {
  Trajectory t;
  t.poses = {{0.0, Pose({0, 0, 0}, 0.0)}, {1.0, Pose({1, 0, 0}, 0.0)}, {2.0, Pose({1, 1, 0}, 0.0)}};
  t.T_V_C = Pose({0.0, 0.0, 0.5}, 0.0);
  EXPECT_LT((t.T_W_V(1.5).translation() - Eigen::Vector3d(1, 0.5, 0)).norm(), 1e-15);
  EXPECT_LT((t.T_W_C(1.5).translation() - Eigen::Vector3d(1, 0.5, 0.5)).norm(), 1e-15);
}

TEST(SceneTrajectory, CheckNamesTheProblem) {
  Trajectory empty;
  EXPECT_THROW(empty.Check(), Error);
  Trajectory unordered = TwoPoses();
  unordered.poses[1].time_s = 1.0;
  try {
    unordered.Check();
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("poses[1].time_s"), std::string::npos) << e.what();
  }
  Trajectory nan = TwoPoses();
  nan.poses[0].T_W_V.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(nan.Check(), Error);
  Trajectory skewed = TwoPoses();
  skewed.T_V_C.linear()(0, 1) = 0.1;
  EXPECT_THROW(skewed.Check(), Error);
}

}  // namespace
}  // namespace uwscan::scanner::sim
