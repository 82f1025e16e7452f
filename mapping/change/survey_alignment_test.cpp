#include "mapping/change/survey_alignment.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace uwscan::mapping {
namespace {

// Two registered 1 m tiles side by side along x, the second placed 2 mm deeper than the first,
// each with its own translation variance; the global transform 1 m off, so that any point it
// places stands out.
SurveyAlignment TwoTiles(double sigma_a_m, double sigma_b_m) {
  SurveyAlignment a;
  a.T_reference_map.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  a.tile_m = 1.0;
  a.tiles.resize(2);
  const double sigmas[2] = {sigma_a_m, sigma_b_m};
  for (int k = 0; k < 2; ++k) {
    SurveyAlignment::Tile& t = a.tiles[static_cast<std::size_t>(k)];
    t.key = Eigen::Vector3i(k, 0, 0);
    t.T_reference_map.translation() = Eigen::Vector3d(0.0, 0.0, 0.002 * k);
    t.covariance.bottomRightCorner<3, 3>() = sigmas[k] * sigmas[k] * Eigen::Matrix3d::Identity();
    t.origin_W = Eigen::Vector3d(k + 0.5, 0.5, 0.5);
    t.registered = true;
  }
  return a;
}

TEST(SurveyAlignment, EachTileHoldsAtItsCentre) {
  const SurveyAlignment a = TwoTiles(0.001, 0.003);
  const Eigen::Vector3d centre_a(0.5, 0.5, 0.5), centre_b(1.5, 0.5, 0.5);
  EXPECT_NEAR((a.Place(centre_a) - centre_a).norm(), 0.0, 1e-12);
  EXPECT_NEAR((a.Place(centre_b) - (centre_b + Eigen::Vector3d(0, 0, 0.002))).norm(), 0.0, 1e-12);
  EXPECT_NEAR(a.SigmaAlongNormal(centre_a, centre_a, Eigen::Vector3d::UnitZ()), 0.001, 1e-12);
  EXPECT_NEAR(a.SigmaAlongNormal(centre_b, centre_b, Eigen::Vector3d::UnitZ()), 0.003, 1e-12);
}

TEST(SurveyAlignment, ThePlacementHasNoStepAtATileBorder) {
  const SurveyAlignment a = TwoTiles(0.001, 0.003);
  const Eigen::Vector3d before(1.0 - 1e-9, 0.3, 0.7), after(1.0 + 1e-9, 0.3, 0.7);
  ASSERT_NE(a.TileOf(before), a.TileOf(after));
  EXPECT_LT((a.Place(before) - a.Place(after)).norm(), 1e-8);
  // Half way between the centres, half of each tile's transform; the two registrations are
  // independent, so their variances add with the weights squared.
  EXPECT_NEAR(a.Place(before).z() - before.z(), 0.001, 1e-8);
  EXPECT_NEAR(a.SigmaAlongNormal(before, before, Eigen::Vector3d::UnitZ()),
              0.5 * std::hypot(0.001, 0.003), 1e-9);
  // A quarter of the way from the first centre to the second.
  const Eigen::Vector3d quarter(0.75, 0.5, 0.5);
  EXPECT_NEAR(a.Place(quarter).z() - quarter.z(), 0.25 * 0.002, 1e-12);
}

TEST(SurveyAlignment, BeyondTheOuterCentresTheNearestTilesHoldAndFarAwayTheGlobalTransform) {
  const SurveyAlignment a = TwoTiles(0.001, 0.003);
  // Past the outer half of a tile no neighbour exists: its own transform alone.
  const Eigen::Vector3d edge(1.9, 0.9, 0.1);
  EXPECT_NEAR(a.Place(edge).z() - edge.z(), 0.002, 1e-12);
  const Eigen::Vector3d far(5.0, 5.0, 5.0);
  EXPECT_NEAR(a.Place(far).z() - far.z(), 1.0, 1e-12);
  EXPECT_EQ(a.SigmaAlongNormal(far, far, Eigen::Vector3d::UnitZ()), 0.0);
  EXPECT_EQ(a.TileOf(far), nullptr);
}

}  // namespace
}  // namespace uwscan::mapping
