#include "ros/conversions/navigation_input.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

Eigen::Isometry3d Pose(const Eigen::Vector3d& p, double yaw, double pitch, double roll) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = p;
  return T;
}

// A vehicle 2 m north, 1 m east and 3 m deep, heading north-east, nose 0.1 rad up, rolled
// 0.2 rad to starboard: in ENU/FLU its position is (1, 2, -3), its yaw 45 degrees (from east,
// counter-clockwise), its pitch -0.1 (FLU's y points left: nose up is a negative turn) and its
// roll still 0.2 (starboard down is a positive turn about forward in both).
TEST(VehiclePoseInUwscanAxes, TurnsAnEnuFluPoseIntoTheSameVehicleInNedFrd) {
  const Eigen::Isometry3d ned = Pose({2, 1, 3}, M_PI / 4, 0.1, 0.2);
  const Eigen::Isometry3d enu = Pose({1, 2, -3}, M_PI / 4, -0.1, 0.2);
  const Eigen::Isometry3d turned = VehiclePoseInUwscanAxes(enu, NavigationAxes::kEnuFlu);
  EXPECT_LT((turned.matrix() - ned.matrix()).norm(), 1e-12) << turned.matrix();
  EXPECT_TRUE(VehiclePoseInUwscanAxes(ned, NavigationAxes::kNedFrd).isApprox(ned, 0.0));
  // The vehicle's forward axis points north-east, up-tilted, in both.
  EXPECT_GT(turned.linear().col(0).x(), 0.0);
  EXPECT_GT(turned.linear().col(0).y(), 0.0);
  EXPECT_LT(turned.linear().col(0).z(), 0.0);  // up is -z in NED
}

TEST(VehiclePoseInNavigationAxes, UndoesVehiclePoseInUwscanAxes) {
  const Eigen::Isometry3d enu = Pose({1, 2, -3}, 0.7, -0.1, 0.2);
  const Eigen::Isometry3d back = VehiclePoseInNavigationAxes(
      VehiclePoseInUwscanAxes(enu, NavigationAxes::kEnuFlu), NavigationAxes::kEnuFlu);
  EXPECT_LT((back.matrix() - enu.matrix()).norm(), 1e-12);
  EXPECT_TRUE(WorldPointInNavigationAxes({2, 1, 3}, NavigationAxes::kEnuFlu)
                  .isApprox(Eigen::Vector3d(1, 2, -3)));
  Covariance6d c = Covariance6d::Zero();
  c.diagonal() << 1, 2, 3, 4, 5, 6;  // north, east, down; about north, east, down
  const Covariance6d enu_c = WorldCovarianceInNavigationAxes(c, NavigationAxes::kEnuFlu);
  EXPECT_EQ(enu_c.diagonal(), (Eigen::Matrix<double, 6, 1>() << 2, 1, 3, 5, 4, 6).finished());
}

// A camera 0.5 m forward and 0.2 m to starboard, looking down: in FLU it sits at (0.5, -0.2, 0)
// and its optical axis (z) is -z; in FRD at (0.5, 0.2, 0), axis +z.
TEST(MountInUwscanAxes, PutsTheCameraWhereItIsOnAForwardRightDownVehicle) {
  Eigen::Isometry3d flu = Eigen::Isometry3d::Identity();
  flu.translation() = Eigen::Vector3d(0.5, -0.2, 0.0);
  flu.linear() << 0, 1, 0, 1, 0, 0, 0, 0, -1;  // camera x to the left, y forward, z down
  const Eigen::Isometry3d frd = MountInUwscanAxes(flu, NavigationAxes::kEnuFlu);
  EXPECT_TRUE(frd.translation().isApprox(Eigen::Vector3d(0.5, 0.2, 0.0)));
  EXPECT_TRUE(frd.linear().col(2).isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_NEAR(frd.linear().determinant(), 1.0, 1e-12);
}

TEST(NavigationFromTransforms, TakesTheOdomToBaseLinkTransformOnly) {
  const RosFrames frames;
  TransformMessage correction{{5.0, "map"}, "odom", Eigen::Isometry3d::Identity()};
  TransformMessage navigation{{5.0, "odom"}, "base_link", Pose({1, 2, 3}, 0.3, 0, 0)};
  EXPECT_FALSE(NavigationFromTransforms({correction}, frames));
  const std::optional<OdometryMessage> m =
      NavigationFromTransforms({correction, navigation}, frames);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->header.stamp_s, 5.0);
  EXPECT_TRUE(m->pose.isApprox(navigation.transform));
}

TEST(ParseNavigation, NamesTheChoicesWhenTheValueIsUnknown) {
  EXPECT_EQ(ParseNavigationSource("tf", "x"), NavigationSource::kTf);
  EXPECT_EQ(ParseNavigationAxes("enu", "x"), NavigationAxes::kEnuFlu);
  try {
    ParseNavigationAxes("nwu", "--navigation-axes");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--navigation-axes: 'nwu', expected ned"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace uwscan::ros
