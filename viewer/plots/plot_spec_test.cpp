#include "viewer/plots/plot_spec.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace uwscan::viewer {
namespace {

TEST(ParetoFront, KeepsOnlyPointsNothingBeatsInBothCoordinates) {
  //                       0    1    2    3    4    5
  const std::vector<double> x = {1.0, 2.0, 3.0, 2.5, 4.0, 1.0};
  const std::vector<double> y = {9.0, 5.0, 1.0, 6.0, 0.5, 10.0};
  EXPECT_EQ(ParetoFront(x, y), (std::vector<std::size_t>{0, 1, 2, 4}));
}

TEST(ParetoFront, NonFinitePointsAreNeverOnIt) {
  const std::vector<double> x = {1.0, NAN, 2.0};
  const std::vector<double> y = {5.0, 0.0, INFINITY};
  EXPECT_EQ(ParetoFront(x, y), (std::vector<std::size_t>{0}));
}

}  // namespace
}  // namespace uwscan::viewer
