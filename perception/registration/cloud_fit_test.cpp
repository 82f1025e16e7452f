#include "perception/registration/cloud_fit.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// A 1 mm grid on the plane z = 0, 100 mm square, far from the origin.
PointCloud Grid(double z_m) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 100; ++j) points.emplace_back(1000.0 + 0.001 * i, -500.0 + 0.001 * j, z_m);
  }
  return MakeCloud(points);
}

TEST(FitOnTargetTest, AnExactCopyMovedBackFitsToNothing) {
  const PointCloud target = Grid(0.0);
  const Eigen::Isometry3d T_target_source =
      Eigen::Translation3d(0.3, -0.2, 0.1) *
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
  const PointCloud source = Transformed(target, T_target_source.inverse());
  const CloudFit fit = FitOnTarget(source, target, T_target_source, 0.001);
  EXPECT_EQ(fit.fitness, 1.0);
  EXPECT_EQ(fit.inliers, target.size());
  EXPECT_LT(fit.inlier_rmse_m, 1e-5);  // float storage far from the origin
}

TEST(FitOnTargetTest, TheDistanceIsToTheNearestTargetPointWithinTheLimit) {
  const PointCloud target = Grid(0.0);
  const PointCloud above = Grid(0.002);
  const CloudFit within = FitOnTarget(above, target, Eigen::Isometry3d::Identity(), 0.005);
  EXPECT_EQ(within.fitness, 1.0);
  EXPECT_NEAR(within.inlier_rmse_m, 0.002, 1e-5);
  const CloudFit beyond = FitOnTarget(above, target, Eigen::Isometry3d::Identity(), 0.001);
  EXPECT_EQ(beyond.fitness, 0.0);
  EXPECT_EQ(beyond.inlier_rmse_m, 0.0);
}

TEST(FitOnTargetTest, BadInputIsRefused) {
  const PointCloud target = Grid(0.0);
  EXPECT_THROW(FitOnTarget(PointCloud{}, target, Eigen::Isometry3d::Identity(), 0.001), Error);
  EXPECT_THROW(FitOnTarget(target, target, Eigen::Isometry3d::Identity(), 0.0), Error);
}

}  // namespace
}  // namespace uwscan::perception
