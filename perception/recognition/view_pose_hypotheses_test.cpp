#include "perception/recognition/view_pose_hypotheses.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <random>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// An L of points about 1 m ahead of its camera (+z), longer one way than the other, so its
// principal axis across the line of sight is well defined.
PointCloud LShape() {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  PointCloud cloud;
  cloud.origin = Eigen::Vector3d(0.05, -0.02, 1.0);
  for (int i = 0; i < 400; ++i) {
    const bool long_arm = i % 3 != 0;
    const Eigen::Vector3d p = long_arm
                                  ? Eigen::Vector3d{0.3 * u(rng), 0.02 * u(rng), 0.01 * u(rng)}
                                  : Eigen::Vector3d{0.02 * u(rng), 0.12 * u(rng), 0.01 * u(rng)};
    cloud.points.push_back(p.cast<float>());
  }
  return cloud;
}

double Gap(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

// The segment is the view rolled about the line of sight through its centroid (and the sensor):
// one of the starts is exactly the true pose, whichever way the principal axis points.
TEST(ViewPoseHypotheses, AViewRolledAboutItsLineOfSightIsAmongTheStarts) {
  ObjectView view;
  view.cloud = LShape();
  view.T_O_C.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).matrix();
  view.T_O_C.translation() = Eigen::Vector3d(0.1, 0.9, -0.4);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < view.cloud.size(); ++i) centroid += view.cloud.Point(i);
  centroid /= static_cast<double>(view.cloud.size());
  for (const double roll : {0.4, 2.5, -1.9}) {
    Eigen::Isometry3d T_S_C = Eigen::Isometry3d::Identity();
    T_S_C.linear() = Eigen::AngleAxisd(roll, centroid.normalized()).matrix();
    const PointCloud segment = Transformed(view.cloud, T_S_C);
    const Eigen::Isometry3d truth = view.T_O_C * T_S_C.inverse();  // T_O_S
    const std::vector<Eigen::Isometry3d> starts = ViewPoseHypotheses(segment, view, 2);
    ASSERT_EQ(starts.size(), 2u);
    EXPECT_LT(std::min(Gap(starts[0], truth), Gap(starts[1], truth)), 1e-6) << "roll " << roll;
    // Twelve rolls: the first two-fold start is still the first.
    const std::vector<Eigen::Isometry3d> twelve = ViewPoseHypotheses(segment, view, 12);
    ASSERT_EQ(twelve.size(), 12u);
    EXPECT_LT(std::min(Gap(twelve[0], truth), Gap(twelve[6], truth)), 1e-6);
  }
}

// Seen from another direction, the start turns the view's line of sight onto the segment's and
// puts the centroids together.
TEST(ViewPoseHypotheses, TheLinesOfSightAndCentroidsAreMadeToAgree) {
  ObjectView view;
  view.cloud = LShape();
  PointCloud segment = LShape();
  segment.origin = Eigen::Vector3d(-0.4, 0.3, 1.3);
  for (const Eigen::Isometry3d& T_O_S : ViewPoseHypotheses(segment, view, 5)) {
    const Eigen::Isometry3d T_C_S = view.T_O_C.inverse() * T_O_S;
    Eigen::Vector3d moved = Eigen::Vector3d::Zero(), stored = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < segment.size(); ++i) moved += T_C_S * segment.Point(i);
    for (std::size_t i = 0; i < view.cloud.size(); ++i) stored += view.cloud.Point(i);
    moved /= static_cast<double>(segment.size());
    stored /= static_cast<double>(view.cloud.size());
    EXPECT_LT((moved - stored).norm(), 1e-9);
    // The sensor (the segment's origin of rays) lands on the view's camera's line of sight.
    const Eigen::Vector3d sensor_C = T_C_S * Eigen::Vector3d::Zero();
    EXPECT_LT(sensor_C.cross(stored).norm() / stored.norm(), 1e-9);
  }
}

TEST(ViewPoseHypotheses, EmptyCloudsAndNoRollsAreRefused) {
  ObjectView view;
  view.cloud = LShape();
  EXPECT_THROW(ViewPoseHypotheses(PointCloud{}, view, 4), Error);
  EXPECT_THROW(ViewPoseHypotheses(LShape(), view, 0), Error);
  PointCloud at_sensor;
  at_sensor.points = {Eigen::Vector3f(0.1f, 0, 0), Eigen::Vector3f(-0.1f, 0, 0)};
  EXPECT_TRUE(ViewPoseHypotheses(at_sensor, view, 4).empty());
}

}  // namespace
}  // namespace uwscan::perception
