#include "perception/cloud/nearest_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// The brute-force answer with the grid's rules: FLANN's float distance, strictly within the
// radius, the lowest index among equally near accepted points.
template <typename Accept>
std::int64_t BruteNearest(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& q,
                          float radius_sq, Accept accept) {
  float best = radius_sq;
  std::int64_t found = -1;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float dx = q.x() - points[i].x(), dy = q.y() - points[i].y(), dz = q.z() - points[i].z();
    float d = 0.0f;
    d += dx * dx;
    d += dy * dy;
    d += dz * dz;
    if (d < best && accept(i)) {
      best = d;
      found = static_cast<std::int64_t>(i);
    }
  }
  return found;
}

// Points on a sphere's surface (an object model sampled about a cell apart) plus a few strays.
std::vector<Eigen::Vector3f> SurfacePoints(std::mt19937& rng, int count) {
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3f u{normal(rng), normal(rng), normal(rng)};
    points.push_back(Eigen::Vector3f(0.3f, -0.1f, 1.2f) + 0.15f * u.normalized());
  }
  points.emplace_back(0.9f, 0.9f, 0.9f);
  return points;
}

TEST(NearestGrid, FindsWhatBruteForceFindsAtEveryRadiusWithAndWithoutAGate) {
  std::mt19937 rng(5);
  const std::vector<Eigen::Vector3f> points = SurfacePoints(rng, 3000);
  const double cell_m = 0.005, max_radius_m = 0.02;
  const NearestGrid grid(points, cell_m, max_radius_m);
  std::uniform_real_distribution<float> box(-0.2f, 0.2f);
  std::normal_distribution<float> off(0.0f, 0.004f);
  int matched = 0, unmatched = 0;
  for (int i = 0; i < 20000; ++i) {
    // Half near the surface (an ICP near convergence), half anywhere around it.
    const Eigen::Vector3f q = i % 2 == 0 ? points[static_cast<std::size_t>(i) % points.size()] +
                                               Eigen::Vector3f{off(rng), off(rng), off(rng)}
                                         : Eigen::Vector3f(0.3f, -0.1f, 1.2f) +
                                               Eigen::Vector3f{box(rng), box(rng), box(rng)};
    for (float radius : {0.02f, 0.01f, 0.0075f, 0.003f}) {
      const float radius_sq = radius * radius;
      const auto all = [](std::size_t) { return true; };
      const auto odd = [](std::size_t j) { return j % 2 == 1; };  // a gate refusing half the points
      const std::int64_t expected = BruteNearest(points, q, radius_sq, all);
      ASSERT_EQ(grid.Nearest(q, radius_sq, all), expected) << "query " << i << " radius " << radius;
      ASSERT_EQ(grid.Nearest(q, radius_sq, odd), BruteNearest(points, q, radius_sq, odd))
          << "query " << i;
      (expected >= 0 ? matched : unmatched) += 1;
    }
  }
  EXPECT_GT(matched, 20000);  // both outcomes were exercised
  EXPECT_GT(unmatched, 10000);
}

TEST(NearestGrid, TakesTheLowestIndexOfEquallyNearPointsAndRefusesTheRadiusItself) {
  // Duplicates and points exactly on cell faces.
  const std::vector<Eigen::Vector3f> points = {{0.01f, 0.0f, 0.0f},
                                               {0.0f, 0.01f, 0.0f},
                                               {0.01f, 0.0f, 0.0f},
                                               {-0.01f, 0.0f, 0.0f},
                                               {0.0f, 0.0f, 0.02f}};
  const NearestGrid grid(points, 0.005, 0.02);
  const auto all = [](std::size_t) { return true; };
  EXPECT_EQ(grid.Nearest(Eigen::Vector3f::Zero(), 0.0004f, all), 0);
  EXPECT_EQ(grid.Nearest(Eigen::Vector3f::Zero(), 0.0004f, [](std::size_t j) { return j != 0; }),
            1);
  EXPECT_EQ(grid.Nearest(Eigen::Vector3f(0.01f, 0.0f, 0.0f), 0.0004f,
                         [](std::size_t j) { return j > 0; }),
            2);
  // Strictly within: a radius equal to the distance finds nothing.
  const float d = 0.01f;
  float d_sq = 0.0f;
  d_sq += d * d;
  EXPECT_EQ(grid.Nearest(Eigen::Vector3f::Zero(), d_sq, all), -1);
  EXPECT_EQ(grid.Nearest(Eigen::Vector3f(5.0f, 5.0f, 5.0f), 0.0004f, all),
            -1);  // far outside the grid
  EXPECT_EQ(grid.Nearest(Eigen::Vector3f(NAN, 0.0f, 0.0f), 0.0004f, all), -1);
}

TEST(NearestGrid, RefusesBadSizesAndAnswersNothingWhenEmpty) {
  const std::vector<Eigen::Vector3f> none;
  const NearestGrid empty(none, 0.005, 0.02);
  EXPECT_EQ(empty.Nearest(Eigen::Vector3f::Zero(), 4e-4f, [](std::size_t) { return true; }), -1);
  EXPECT_THROW(NearestGrid(none, 0.0, 0.02), Error);
  EXPECT_THROW(NearestGrid(none, 0.005, 0.001), Error);
  const std::vector<Eigen::Vector3f> bad = {{NAN, 0.0f, 0.0f}};
  EXPECT_THROW(NearestGrid(bad, 0.005, 0.02), Error);
}

TEST(NearestGrid, AWideCloudGetsWiderCellsAndStaysExact) {
  // A kilometre across at 1 mm cells would be 10^18 cells: the grid widens its cells instead.
  std::mt19937 rng(9);
  std::vector<Eigen::Vector3f> points = SurfacePoints(rng, 500);
  points.emplace_back(1000.0f, 1000.0f, 1000.0f);
  const NearestGrid grid(points, 0.001, 0.002);
  const auto all = [](std::size_t) { return true; };
  std::normal_distribution<float> off(0.0f, 0.001f);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f q = points[i] + Eigen::Vector3f{off(rng), off(rng), off(rng)};
    ASSERT_EQ(grid.Nearest(q, 4e-6f, all), BruteNearest(points, q, 4e-6f, all)) << "point " << i;
  }
}

}  // namespace
}  // namespace uwscan::perception
