#include "scanner/sim/depth_camera.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::scanner::sim {
namespace {

// A 4 m x 4 m plane at z = depth in front of a camera at the origin looking along +z.
std::vector<SceneObject> WallAt(double depth_m) {
  SceneObject wall;
  wall.name = "wall";
  wall.shape = ObjectShape::kPlane;
  wall.mesh = MakeRectangle(4.0, 4.0);
  wall.T_W_O.linear() = Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).matrix();
  wall.T_W_O.translation() = Eigen::Vector3d(0.0, 0.0, depth_m);
  return {wall};
}

TEST(DepthCamera, WithoutNoiseEveryPixelLiesOnTheSurfaceAlongItsOwnRay) {
  DepthCameraOptions options;
  options.noise_per_m = 0.0;
  const DepthScan scan =
      ScanWithDepthCamera(WallAt(1.5), Eigen::Isometry3d::Identity(), options, 1);
  ASSERT_EQ(scan.points_C.size(), static_cast<std::size_t>(options.width_px * options.height_px));
  const double focal_px = 0.5 * options.width_px / std::tan(0.5 * options.horizontal_fov_rad);
  for (std::size_t i = 0; i < scan.points_C.size(); ++i) {
    const Eigen::Vector3d& p = scan.points_C[i];
    EXPECT_NEAR(p.z(), 1.5, 1e-9);
    // The first pixel's centre, and the last's, project where the pinhole says.
    if (i == 0) {
      EXPECT_NEAR(focal_px * p.x() / p.z(), 0.5 - 0.5 * options.width_px, 1e-6);
      EXPECT_NEAR(focal_px * p.y() / p.z(), 0.5 - 0.5 * options.height_px, 1e-6);
    }
    EXPECT_EQ(scan.object_index[i], 0);
  }
}

TEST(DepthCamera, DepthNoiseGrowsWithTheSquareOfTheDepth) {
  DepthCameraOptions options;
  for (const double depth_m : {1.0, 2.0}) {
    const DepthScan scan =
        ScanWithDepthCamera(WallAt(depth_m), Eigen::Isometry3d::Identity(), options, 7);
    double sum_sq = 0.0;
    for (const Eigen::Vector3d& p : scan.points_C) sum_sq += (p.z() - depth_m) * (p.z() - depth_m);
    const double sigma = std::sqrt(sum_sq / static_cast<double>(scan.points_C.size()));
    const double expected = options.noise_per_m * depth_m * depth_m;
    // 76,800 draws: the sample std is within 1 % of the truth at many standard errors.
    EXPECT_NEAR(sigma, expected, 0.01 * expected) << depth_m;
  }
}

TEST(DepthCamera, SameSeedSameScanOutOfRangeLeftOut) {
  DepthCameraOptions options;
  const Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  const DepthScan a = ScanWithDepthCamera(WallAt(1.0), T_W_C, options, 3);
  const DepthScan b = ScanWithDepthCamera(WallAt(1.0), T_W_C, options, 3);
  const DepthScan c = ScanWithDepthCamera(WallAt(1.0), T_W_C, options, 4);
  EXPECT_EQ(a.points_C, b.points_C);
  EXPECT_NE(a.points_C, c.points_C);
  EXPECT_TRUE(ScanWithDepthCamera(WallAt(5.0), T_W_C, options, 3).points_C.empty());
  EXPECT_TRUE(ScanWithDepthCamera(WallAt(0.2), T_W_C, options, 3).points_C.empty());
  options.max_range_m = options.min_range_m;
  EXPECT_THROW(ScanWithDepthCamera(WallAt(1.0), T_W_C, options, 3), Error);
}

}  // namespace
}  // namespace uwscan::scanner::sim
