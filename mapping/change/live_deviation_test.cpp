#include "mapping/change/live_deviation.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// A seabed reference (a 1 m square at 10 m, NED) without normals, as an earlier survey's cloud.
Survey Seabed() {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 100; ++j) points.emplace_back(0.01 * i, 0.01 * j, 10.0);
  }
  Survey s;
  s.name = "seabed";
  s.cloud = perception::MakeCloud(points);
  return s;
}

TEST(LiveDeviation, SignedAlongTheReferencesUpwardNormalBlankWithinTheThresholdOrFarAway) {
  const LiveDeviation live(Seabed());  // threshold 3 mm, 5 cm reach
  const std::vector<Eigen::Vector3d> points = {
      {0.5, 0.5, 10.0 - 0.008},  // 8 mm above the seabed (NED: smaller z): gained
      {0.3, 0.6, 10.0 + 0.006},  // 6 mm below: lost
      {0.4, 0.4, 10.0 - 0.001},  // within the threshold
      {3.0, 3.0, 10.0}};         // no reference near
  const std::vector<float> d = live.Deviations(points);
  ASSERT_EQ(d.size(), 4u);
  EXPECT_NEAR(d[0], 0.008, 1e-5);
  EXPECT_NEAR(d[1], -0.006, 1e-5);
  EXPECT_TRUE(std::isnan(d[2]));
  EXPECT_TRUE(std::isnan(d[3]));
  Survey empty;
  EXPECT_THROW(LiveDeviation{empty}, Error);
  LiveDeviationOptions bad;
  bad.threshold_m = -1.0;
  EXPECT_THROW(LiveDeviation(Seabed(), bad), Error);
}

}  // namespace
}  // namespace uwscan::mapping
