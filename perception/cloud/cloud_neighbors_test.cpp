#include "perception/cloud/cloud_neighbors.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

std::vector<Eigen::Vector3f> RandomPoints(std::size_t n, float extent, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  std::vector<Eigen::Vector3f> points(n);
  for (auto& p : points) p = {u(rng), u(rng), 0.2f * u(rng)};
  return points;
}

// Brute force with FLANN's distance and strict test.
std::vector<std::pair<std::uint32_t, float>> BruteRadius(const std::vector<Eigen::Vector3f>& pts,
                                                         const Eigen::Vector3f& q, double r) {
  const float r2 = static_cast<float>(r * r);
  std::vector<std::pair<std::uint32_t, float>> out;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    float d = 0.0f;
    for (int a = 0; a < 3; ++a) {
      const float diff = q[a] - pts[i][a];
      d += diff * diff;
    }
    if (d < r2) out.emplace_back(static_cast<std::uint32_t>(i), d);
  }
  return out;
}

std::vector<std::pair<std::uint32_t, float>> Sorted(const std::vector<std::uint32_t>& idx,
                                                    const std::vector<float>& d2) {
  std::vector<std::pair<std::uint32_t, float>> out;
  for (std::size_t i = 0; i < idx.size(); ++i) out.emplace_back(idx[i], d2[i]);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(RadiusGrid, MatchesBruteForceDenseAndSparse) {
  const std::vector<Eigen::Vector3f> points = RandomPoints(3000, 1.0f, 1);
  // 0.08 m: dense cell array; 0.003 m: sparse cells (far more cells than points).
  for (double radius : {0.08, 0.003}) {
    const RadiusGrid grid(points, radius);
    std::vector<std::uint32_t> idx;
    std::vector<float> d2;
    for (std::size_t i = 0; i < points.size(); i += 7) {
      grid.Query(points[i], idx, d2);
      EXPECT_EQ(Sorted(idx, d2), BruteRadius(points, points[i], radius)) << "radius " << radius;
    }
    // Queries off the cloud, including far outside it.
    for (const Eigen::Vector3f& q :
         {Eigen::Vector3f(0.5f, -0.3f, 0.01f), Eigen::Vector3f(1.05f, 1.02f, 0.0f),
          Eigen::Vector3f(1e30f, 0.0f, 0.0f)}) {
      grid.Query(q, idx, d2);
      EXPECT_EQ(Sorted(idx, d2), BruteRadius(points, q, radius));
    }
  }
}

TEST(RadiusGrid, EmptyCloudAndBadRadius) {
  const std::vector<Eigen::Vector3f> none;
  const RadiusGrid grid(none, 0.1);
  std::vector<std::uint32_t> idx{1};
  std::vector<float> d2{1.0f};
  grid.Query(Eigen::Vector3f::Zero(), idx, d2);
  EXPECT_TRUE(idx.empty());
  EXPECT_TRUE(d2.empty());
  EXPECT_THROW(RadiusGrid(none, 0.0), Error);
  EXPECT_THROW(RadiusGrid(none, std::nan("")), Error);
  const std::vector<Eigen::Vector3f> wide = {Eigen::Vector3f::Zero(), Eigen::Vector3f(1e3f, 0, 0)};
  EXPECT_THROW(RadiusGrid(wide, 1e-6), Error);  // 1e9 cells along x
}

TEST(KnnIndex, MatchesBruteForce) {
  const std::vector<Eigen::Vector3f> points = RandomPoints(2000, 1.0f, 2);
  const KnnIndex index(points);
  std::vector<std::uint32_t> idx;
  std::vector<float> d2;
  for (std::size_t i = 0; i < points.size(); i += 13) {
    index.Query(points[i], 10, idx, d2);
    ASSERT_EQ(idx.size(), 10u);
    EXPECT_EQ(idx[0], i);
    EXPECT_EQ(d2[0], 0.0f);
    std::vector<float> all;
    for (const Eigen::Vector3f& p : points) all.push_back((p - points[i]).squaredNorm());
    std::sort(all.begin(), all.end());
    for (std::size_t j = 0; j < 10; ++j) {
      EXPECT_NEAR(d2[j], all[j], 1e-6f);
      EXPECT_NEAR((points[idx[j]] - points[i]).squaredNorm(), d2[j], 1e-6f);
    }
  }
  index.Query(points[0], 5000, idx, d2);  // more than the cloud holds
  EXPECT_EQ(idx.size(), points.size());
  EXPECT_TRUE(std::is_sorted(d2.begin(), d2.end()));
}

TEST(KnnIndex, EmptyCloud) {
  const std::vector<Eigen::Vector3f> none;
  const KnnIndex index(none);
  std::vector<std::uint32_t> idx;
  std::vector<float> d2;
  index.Query(Eigen::Vector3f::Zero(), 3, idx, d2);
  EXPECT_TRUE(idx.empty());
}

}  // namespace
}  // namespace uwscan::perception
