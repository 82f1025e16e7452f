#include "mapping/slam/submap_centre_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// The indices whose centre lies within radius of p, by looking at every one.
std::vector<int> WithinByScan(const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& p,
                              double radius_m) {
  std::vector<int> within;
  for (int i = 0; i < static_cast<int>(centres.size()); ++i)
    if ((centres[static_cast<std::size_t>(i)] - p).norm() <= radius_m) within.push_back(i);
  return within;
}

bool Contains(const std::vector<int>& sorted, int i) {
  return std::binary_search(sorted.begin(), sorted.end(), i);
}

// A dive's worth of centres along a wandering track, moved again and again as solves move
// them (some a few millimetres, some across cells): every query holds every centre within reach,
// in ascending order, whatever moved before it.
TEST(SubmapCentreGrid, FindsEveryCentreWithinReachAsTheyMove) {
  std::mt19937 random(7);
  std::normal_distribution<double> step(0.0, 0.3), nudge(0.0, 0.02), jump(0.0, 1.5);
  std::uniform_int_distribution<int> coin(0, 9);
  SubmapCentreGrid grid(2.0);
  std::vector<Eigen::Vector3d> centres;
  Eigen::Vector3d p = Eigen::Vector3d(-3.0, 0.5, 12.0);
  for (int k = 0; k < 2000; ++k) {
    p += Eigen::Vector3d(step(random), step(random), 0.1 * step(random));
    centres.push_back(p);
    grid.Place(k, p);
    // A solve moves the last stretch of the track, some of it far.
    if (k % 50 == 49) {
      for (int j = k - 40; j <= k; ++j) {
        Eigen::Vector3d& c = centres[static_cast<std::size_t>(j)];
        c += coin(random) == 0 ? Eigen::Vector3d(jump(random), jump(random), jump(random))
                               : Eigen::Vector3d(nudge(random), nudge(random), nudge(random));
        grid.Place(j, c);
      }
    }
    const double radius_m = 0.5 + 3.0 * (k % 7) / 7.0;
    const std::vector<int> near = grid.Near(centres[static_cast<std::size_t>(k / 2)], radius_m);
    ASSERT_TRUE(std::is_sorted(near.begin(), near.end()));
    ASSERT_EQ(std::adjacent_find(near.begin(), near.end()), near.end()) << "a centre held twice";
    for (const int i : WithinByScan(centres, centres[static_cast<std::size_t>(k / 2)], radius_m))
      ASSERT_TRUE(Contains(near, i)) << "submap " << i << " missed at step " << k;
  }
  EXPECT_EQ(grid.held(), 2000);
}

// A query far from every centre visits its few cells and finds nothing; one on a centre finds
// it alone, however many the grid holds elsewhere.
TEST(SubmapCentreGrid, AnEmptyNeighbourhoodIsEmpty) {
  SubmapCentreGrid grid(1.0);
  for (int k = 0; k < 100; ++k) grid.Place(k, Eigen::Vector3d(10.0 * k, 0.0, 0.0));
  EXPECT_TRUE(grid.Near(Eigen::Vector3d(5.0, 5.0, 5.0), 1.0).empty());
  EXPECT_EQ(grid.Near(Eigen::Vector3d(300.2, 0.0, 0.0), 0.5), std::vector<int>{30});
}

// Centres beyond the cells' range are held at its edge, where a query at the same place finds
// them; what cannot be a place is refused by name.
TEST(SubmapCentreGrid, FarCentresAreFoundAndNonFiniteOnesRefused) {
  SubmapCentreGrid grid(1.0);
  const Eigen::Vector3d far(5e9, -5e9, 0.0);
  grid.Place(0, far);
  EXPECT_EQ(grid.Near(far, 1.0), std::vector<int>{0});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(grid.Place(1, Eigen::Vector3d(nan, 0.0, 0.0)), Error);
  EXPECT_THROW(grid.Place(-1, Eigen::Vector3d::Zero()), Error);
  EXPECT_THROW(grid.Near(Eigen::Vector3d::Zero(), -1.0), Error);
  EXPECT_THROW(SubmapCentreGrid(0.0), Error);
  EXPECT_EQ(grid.held(), 1);
}

}  // namespace
}  // namespace uwscan::mapping
