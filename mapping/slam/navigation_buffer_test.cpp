#include "mapping/slam/navigation_buffer.hpp"

#include <gtest/gtest.h>

#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

NavigationRecord At(double time_s, double x_m) {
  NavigationRecord r;
  r.time_s = time_s;
  r.T_W_V = Eigen::Isometry3d::Identity();
  r.T_W_V.translation().x() = x_m;
  return r;
}

TEST(NavigationBuffer, InterpolatesBetweenSamplesAndMeasuresTheGapAcross) {
  NavigationBuffer nav;
  for (const auto& [t, x] : {std::pair{0.0, 0.0}, {0.05, 0.01}, {0.10, 0.02}, {3.10, 0.62}})
    nav.Add(At(t, x));
  EXPECT_NEAR(nav.T_W_V(0.075).translation().x(), 0.015, 1e-12);
  EXPECT_DOUBLE_EQ(nav.GapAround(0.05), 0.0);  // at a sample: nothing to bridge
  EXPECT_NEAR(nav.GapAround(0.07), 0.05, 1e-12);
  EXPECT_NEAR(nav.GapAround(1.0), 3.0, 1e-12);  // inside the dropout
  EXPECT_NEAR(nav.GapAround(3.10), 0.0, 1e-12);
}

TEST(NavigationBuffer, OutsideItsSpanItSaysWhereItsSamplesAre) {
  NavigationBuffer nav;
  EXPECT_THROW(nav.GapAround(0.0), Error);
  nav.Add(At(1.0, 0.0));
  nav.Add(At(2.0, 0.0));
  try {
    nav.GapAround(2.5);
    FAIL() << "no error after the last sample";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("navigation spans 1.000000 to 2.000000 s"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(nav.T_W_V(0.5), Error);
}

TEST(NavigationBuffer, HeldTimeStaysWithinTheSamples) {
  NavigationBuffer nav;
  nav.Add(At(1.0, 0.0));
  nav.Add(At(2.0, 0.5));
  EXPECT_EQ(nav.HeldTime(0.2), 1.0);
  EXPECT_EQ(nav.HeldTime(1.25), 1.25);
  EXPECT_EQ(nav.HeldTime(7.0), 2.0);
  EXPECT_EQ(nav.T_W_V(nav.HeldTime(7.0)).translation().x(), 0.5);
}

}  // namespace
}  // namespace uwscan::mapping
