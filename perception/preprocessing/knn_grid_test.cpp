#include "perception/preprocessing/knn_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "perception/cloud/flann_distance.hpp"
#include "perception/preprocessing/normals.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

using Neighbours = std::vector<std::vector<std::uint32_t>>;

// Every point's k nearest by sorting all points: FLANN's distance, then the lower index.
Neighbours BruteForce(const std::vector<Eigen::Vector3f>& points, int k) {
  Neighbours all(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::vector<std::pair<float, std::uint32_t>> order;
    for (std::size_t j = 0; j < points.size(); ++j) {
      const Eigen::Vector3f& a = points[i];
      const Eigen::Vector3f& b = points[j];
      order.emplace_back(FlannSquaredDistance(a.x(), a.y(), a.z(), b.x(), b.y(), b.z()),
                         static_cast<std::uint32_t>(j));
    }
    std::sort(order.begin(), order.end());
    const std::size_t count = std::min(order.size(), static_cast<std::size_t>(k));
    for (std::size_t r = 0; r < count; ++r) all[i].push_back(order[r].second);
  }
  return all;
}

Neighbours OnGrid(const std::vector<Eigen::Vector3f>& points, double cell_m, int k, int threads) {
  Neighbours all(points.size());
  std::vector<int> visits(points.size(), 0);
  KnnGrid(points, cell_m)
      .ForEachPoint(k, threads, [&](std::size_t i, std::span<const std::uint32_t> neighbours) {
        all[i].assign(neighbours.begin(), neighbours.end());
        ++visits[i];
      });
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_EQ(visits[i], 1) << "point " << i;
  return all;
}

// A wavy surface sampled about 5 mm apart with jitter, a dense clump, and a few points far out.
std::vector<Eigen::Vector3f> SurfaceWithOutliers() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-0.002f, 0.002f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      const float x = 0.005f * static_cast<float>(i) + jitter(rng);
      const float y = 0.005f * static_cast<float>(j) + jitter(rng);
      points.emplace_back(x, y, 0.02f * std::sin(20.0f * x) + jitter(rng));
    }
  }
  for (int i = 0; i < 100; ++i) {
    points.emplace_back(0.1f + 0.1f * jitter(rng), 0.1f + 0.1f * jitter(rng), 0.1f * jitter(rng));
  }
  points.emplace_back(1.0f, 0.0f, 0.0f);
  points.emplace_back(0.0f, -2.0f, 0.5f);
  points.emplace_back(0.3f, 0.3f, 0.3f);
  return points;
}

TEST(KnnGrid, FindsTheKNearestOfEveryPointAsBruteForceDoes) {
  const std::vector<Eigen::Vector3f> points = SurfaceWithOutliers();
  for (int k : {1, 15, 40}) {
    const Neighbours truth = BruteForce(points, k);
    // Cells about the k-th neighbour's distance, far smaller (every point on the kd-tree) and
    // far larger (blocks of thousands).
    for (double cell : {0.0125, 1e-4, 0.3}) {
      EXPECT_EQ(OnGrid(points, cell, k, 2), truth) << "k " << k << ", cell " << cell;
    }
  }
}

// On a lattice with exact float coordinates many points are equally near: the lower index wins.
TEST(KnnGrid, OfEquallyNearPointsTakesTheLowerIndex) {
  std::vector<Eigen::Vector3f> points;
  for (int x = 0; x < 6; ++x) {
    for (int y = 0; y < 5; ++y) {
      for (int z = 0; z < 4; ++z) points.emplace_back(0.25f * x, 0.25f * y, 0.25f * z);
    }
  }
  std::reverse(points.begin(), points.end());  // indices not in the grid's own order
  for (int k : {2, 5, 10, 20}) {
    EXPECT_EQ(OnGrid(points, 0.75, k, 2), BruteForce(points, k)) << "k " << k;
  }
}

TEST(KnnGrid, SameNeighboursOnOneThreadAndTwo) {
  const std::vector<Eigen::Vector3f> points = SurfaceWithOutliers();
  EXPECT_EQ(OnGrid(points, 0.0125, 15, 1), OnGrid(points, 0.0125, 15, 2));
}

TEST(KnnGrid, SmallCloudsAndKBeyondTheirSize) {
  const std::vector<Eigen::Vector3f> one = {{1.0f, 2.0f, 3.0f}};
  EXPECT_EQ(OnGrid(one, 0.01, 5, 1), Neighbours{{0}});
  const std::vector<Eigen::Vector3f> none;
  EXPECT_TRUE(OnGrid(none, 0.01, 5, 1).empty());
  const std::vector<Eigen::Vector3f> three = {
      {0.0f, 0.0f, 0.0f}, {5.0f, 0.0f, 0.0f}, {0.0f, 0.1f, 0.0f}};
  EXPECT_EQ(OnGrid(three, 0.01, 3, 1), BruteForce(three, 3));
}

TEST(KnnGrid, RefusesBadInput) {
  const std::vector<Eigen::Vector3f> points = {{0.0f, 0.0f, 0.0f}};
  EXPECT_THROW(KnnGrid(points, 0.0), Error);
  EXPECT_THROW(KnnGrid(points, std::numeric_limits<double>::quiet_NaN()), Error);
  const std::vector<Eigen::Vector3f> bad = {{0.0f, std::numeric_limits<float>::infinity(), 0.0f}};
  EXPECT_THROW(KnnGrid(bad, 0.01), Error);
  const std::vector<Eigen::Vector3f> far = {{1e9f, 0.0f, 0.0f}};
  EXPECT_THROW(KnnGrid(far, 1e-6), Error);
  const KnnGrid grid(points, 0.01);
  EXPECT_THROW(grid.ForEachPoint(0, 1, [](std::size_t, std::span<const std::uint32_t>) {}), Error);
}

TEST(KnnGrid, RethrowsWhatTheVisitThrows) {
  const std::vector<Eigen::Vector3f> points = SurfaceWithOutliers();
  const KnnGrid grid(points, 0.0125);
  EXPECT_THROW(grid.ForEachPoint(3, 2,
                                 [](std::size_t i, std::span<const std::uint32_t>) {
                                   if (i == 17) throw Error("seventeen");
                                 }),
               Error);
}

// Without ties the neighbours come in the kd-tree's order, so the normals match to the bit.
TEST(KnnGrid, NormalsOnTheGridEqualTheKdTreesToTheBit) {
  PointCloud cloud;
  cloud.origin = Eigen::Vector3d(10.0, -3.0, 2.0);
  cloud.points = SurfaceWithOutliers();
  NormalOptions options;
  options.k = 15;
  options.viewpoint = cloud.origin + Eigen::Vector3d(0.1, 0.1, 1.0);
  const NormalsResult tree = EstimateNormals(cloud, options);
  options.knn_cell_m = 0.0125;
  const NormalsResult grid = EstimateNormals(cloud, options);
  ASSERT_EQ(grid.normals.size(), tree.normals.size());
  EXPECT_EQ(grid.num_invalid, tree.num_invalid);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      if (std::isnan(tree.normals[i][a])) {
        EXPECT_TRUE(std::isnan(grid.normals[i][a])) << "point " << i;
      } else {
        EXPECT_EQ(grid.normals[i][a], tree.normals[i][a]) << "point " << i;
      }
    }
  }
}

}  // namespace
}  // namespace uwscan::perception
