#include "perception/preprocessing/voxel_filter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// A 4 x 3 x 2 block of voxels of edge 0.1 m anchored at `corner` (a multiple of the leaf), with
// 1 + (i + j + k) % 3 points per voxel scattered around its centre by up to 0.03 m.
struct GridScene {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> centroids;  // expected, ordered by voxel key
};

GridScene MakeGridScene(const Eigen::Vector3d& corner) {
  GridScene scene;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> jitter(-0.03, 0.03);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 2; ++k) {
        const Eigen::Vector3d centre = corner + 0.1 * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        const int count = 1 + (i + j + k) % 3;
        for (int c = 0; c < count; ++c) {
          const Eigen::Vector3d p = centre + Eigen::Vector3d{jitter(rng), jitter(rng), jitter(rng)};
          scene.points.push_back(p);
          sum += p;
        }
        scene.centroids.push_back(sum / count);
      }
    }
  }
  return scene;
}

TEST(VoxelDownsample, CountsAndCentroidsOnKnownGrid) {
  const GridScene scene = MakeGridScene(Eigen::Vector3d(-0.2, 0.3, 1.0));
  const PointCloud cloud = MakeCloud(scene.points);
  const PointCloud out = VoxelDownsample(cloud, {.leaf_m = 0.1});
  ASSERT_EQ(out.size(), 24u);
  EXPECT_EQ(out.origin, cloud.origin);
  EXPECT_FALSE(out.has_normals());
  for (std::size_t v = 0; v < out.size(); ++v) {
    EXPECT_LT((out.Point(v) - scene.centroids[v]).norm(), 1e-6) << "voxel " << v;
  }
}

TEST(VoxelDownsample, DeterministicAndIndependentOfInputOrder) {
  GridScene scene = MakeGridScene(Eigen::Vector3d::Zero());
  const PointCloud a = VoxelDownsample(MakeCloud(scene.points), {.leaf_m = 0.1});
  std::mt19937_64 rng(5);
  std::shuffle(scene.points.begin(), scene.points.end(), rng);
  const PointCloud b = VoxelDownsample(MakeCloud(scene.points), {.leaf_m = 0.1});
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t v = 0; v < a.size(); ++v) {
    EXPECT_LT((a.Point(v) - b.Point(v)).norm(), 1e-6);
  }
  const PointCloud again = VoxelDownsample(MakeCloud(scene.points), {.leaf_m = 0.1});
  EXPECT_EQ(again.points, b.points);
}

TEST(VoxelDownsample, HugeCoordinatesGiveTheSameResultAsAtTheOrigin) {
  const GridScene scene = MakeGridScene(Eigen::Vector3d::Zero());
  PointCloud near = MakeCloud(scene.points);
  PointCloud far = near;  // the same float offsets about an origin 1e6 m away
  far.origin += Eigen::Vector3d(1e6, -1e6, 1e6);
  const PointCloud a = VoxelDownsample(near, {.leaf_m = 0.1});
  const PointCloud b = VoxelDownsample(far, {.leaf_m = 0.1});
  ASSERT_EQ(a.size(), 24u);
  ASSERT_EQ(b.size(), a.size());
  EXPECT_EQ(b.origin, far.origin);
  EXPECT_EQ(a.points, b.points);  // identical float offsets
  for (std::size_t v = 0; v < a.size(); ++v) {
    EXPECT_LT((b.Point(v) - a.Point(v) - Eigen::Vector3d(1e6, -1e6, 1e6)).norm(), 1e-6);
  }
}

TEST(VoxelDownsample, EmptyOnePointAndCollinear) {
  EXPECT_TRUE(VoxelDownsample(PointCloud{}, {.leaf_m = 0.1}).empty());
  const std::vector<Eigen::Vector3d> one = {{1.0, 2.0, 3.0}};
  const PointCloud single = VoxelDownsample(MakeCloud(one), {.leaf_m = 0.1});
  ASSERT_EQ(single.size(), 1u);
  EXPECT_LT((single.Point(0) - one[0]).norm(), 1e-9);
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 100; ++i) line.emplace_back(0.01 * i + 0.005, 0.0, 0.0);
  EXPECT_EQ(VoxelDownsample(MakeCloud(line), {.leaf_m = 0.1}).size(), 10u);
}

TEST(VoxelDownsample, RejectsBadInput) {
  PointCloud cloud = MakeCloud(MakeGridScene(Eigen::Vector3d::Zero()).points);
  EXPECT_THROW(VoxelDownsample(cloud, {.leaf_m = 0.0}), Error);
  EXPECT_THROW(VoxelDownsample(cloud, {.leaf_m = -1.0}), Error);
  EXPECT_THROW(VoxelDownsample(cloud, {.leaf_m = std::nan("")}), Error);
  // Keys beyond 64 bits: a clear error, not an overflow.
  EXPECT_THROW(VoxelDownsample(cloud, {.leaf_m = 1e-300}), Error);
  cloud.points[3].x() = std::numeric_limits<float>::quiet_NaN();
  try {
    VoxelDownsample(cloud, {.leaf_m = 0.1});
    FAIL() << "NaN point accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("point 3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::perception
