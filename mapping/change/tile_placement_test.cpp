#include "mapping/change/tile_placement.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// Two poses 1 m apart, each nearest to one of two points on the seabed below them, both in one
// tile: each pose holds half of the tile.
struct TwoLegs {
  Survey survey;
  std::vector<Eigen::Vector3d> points = {{0.0, 0.0, 1.0}, {1.0, 0.0, 1.0}};
  std::vector<Eigen::Vector3d> normals = {-Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
  std::vector<long> tile_of = {0, 0};

  // Position covariance sigma^2 per axis for each pose and `correlation` between the two poses'
  // same axes; no rotation error.
  explicit TwoLegs(double sigma_m, double correlation) {
    survey.name = "two legs";
    survey.kind = SurveyKind::kMap;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    survey.poses = {T, T};
    survey.poses[1].translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
    // The information of that covariance, rotations pinned hard (their variance negligible).
    Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(12, 12);
    for (int a = 0; a < 2; ++a) {
      covariance.block<3, 3>(6 * a, 6 * a) = 1e-20 * Eigen::Matrix3d::Identity();
      for (int b = 0; b < 2; ++b) {
        const double c = (a == b ? 1.0 : correlation) * sigma_m * sigma_m;
        covariance.block<3, 3>(6 * a + 3, 6 * b + 3) = c * Eigen::Matrix3d::Identity();
      }
    }
    survey.joint_uncertainty = std::make_shared<const JointPoseUncertainty>(
        Eigen::MatrixXd(covariance.inverse()).sparseView(), std::vector<int>{0, 6});
  }
};

// Poses whose errors are correlated by rho leave only what they do not share: a point placed by
// pose 0 moves by (e_0 - e_1) / 2 against the tile, of variance sigma^2 (1 - rho) / 2.
TEST(TileRelativePoseSigmas, CorrelatedPosesLeaveOnlyWhatTheyDoNotShare) {
  const TwoLegs legs(0.004, 0.99);
  for (double sigma :
       TileRelativePoseSigmas(legs.survey, legs.points, legs.normals, legs.tile_of, 0.0))
    EXPECT_NEAR(sigma, 0.004 * std::sqrt(0.01 / 2.0), 1e-9);
}

// Independent poses (rho = 0): sigma^2 / 2.
TEST(TileRelativePoseSigmas, IndependentPosesLeaveHalfOfTheirVariance) {
  const TwoLegs legs(0.004, 0.0);
  for (double sigma :
       TileRelativePoseSigmas(legs.survey, legs.points, legs.normals, legs.tile_of, 0.0))
    EXPECT_NEAR(sigma, 0.004 / std::sqrt(2.0), 1e-12);
}

// Each pose a tile of its own: the tile's registration takes out all of the pose's error.
TEST(TileRelativePoseSigmas, APoseAloneInItsTileLeavesNothing) {
  const TwoLegs legs(0.004, 0.0);
  for (double sigma : TileRelativePoseSigmas(legs.survey, legs.points, legs.normals, {0, 1}, 0.0))
    EXPECT_NEAR(sigma, 0.0, 1e-12);
}

// Both points seen from both poses (within 2 m of the nearest): each moves as the tile does.
TEST(TileRelativePoseSigmas, PointsSeenFromEveryPoseOfTheirTileLeaveNothing) {
  const TwoLegs legs(0.004, 0.0);
  for (double sigma :
       TileRelativePoseSigmas(legs.survey, legs.points, legs.normals, legs.tile_of, 2.0))
    EXPECT_NEAR(sigma, 0.0, 1e-12);
}

TEST(TileRelativePoseSigmas, WithoutAJointUncertaintyNothingIsAdded) {
  TwoLegs legs(0.004, 0.0);
  legs.survey.joint_uncertainty.reset();
  for (double sigma :
       TileRelativePoseSigmas(legs.survey, legs.points, legs.normals, legs.tile_of, 0.0))
    EXPECT_EQ(sigma, 0.0);
  // One holding another number of poses than the trajectory is refused.
  legs.survey.joint_uncertainty = std::make_shared<const JointPoseUncertainty>(
      Eigen::MatrixXd(Eigen::MatrixXd::Identity(6, 6)).sparseView(), std::vector<int>{0});
  EXPECT_THROW(TileRelativePoseSigmas(legs.survey, legs.points, legs.normals, legs.tile_of, 0.0),
               Error);
}

}  // namespace
}  // namespace uwscan::mapping
