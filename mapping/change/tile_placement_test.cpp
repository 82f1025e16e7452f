#include "mapping/change/tile_placement.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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

// The header's formula evaluated directly: for each point, the poses within seen_within_m of the
// nearest, each pose's weight in the point's tile, and the variance of
// n . sum_i c_i (w_i x (p - t_i) + v_i) under the joint covariance.
std::vector<double> DirectSigmas(const std::vector<Eigen::Isometry3d>& poses,
                                 const Eigen::MatrixXd& covariance,
                                 const std::vector<Eigen::Vector3d>& points,
                                 const std::vector<Eigen::Vector3d>& normals,
                                 const std::vector<long>& tile_of, double seen_within_m) {
  const std::size_t n = poses.size();
  std::vector<Eigen::VectorXd> shares;  // per point, per pose
  for (const Eigen::Vector3d& p : points) {
    Eigen::VectorXd distance(static_cast<Eigen::Index>(n));
    for (std::size_t i = 0; i < n; ++i)
      distance(static_cast<Eigen::Index>(i)) = (p - poses[i].translation()).norm();
    const Eigen::VectorXd seen =
        (distance.array() <= distance.minCoeff() + seen_within_m).cast<double>();
    shares.push_back(seen / seen.sum());
  }
  std::vector<double> sigma;
  for (std::size_t c = 0; c < points.size(); ++c) {
    Eigen::VectorXd weight = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
    int in_tile = 0;
    for (std::size_t d = 0; d < points.size(); ++d) {
      if (tile_of[d] != tile_of[c]) continue;
      weight += shares[d];
      ++in_tile;
    }
    const Eigen::VectorXd coefficient = shares[c] - weight / in_tile;
    Eigen::RowVectorXd h(static_cast<Eigen::Index>(6 * n));
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d lever = (points[c] - poses[i].translation()).cross(normals[c]);
      h.segment<3>(static_cast<Eigen::Index>(6 * i)) = lever.transpose();
      h.segment<3>(static_cast<Eigen::Index>(6 * i + 3)) = normals[c].transpose();
      h.segment<6>(static_cast<Eigen::Index>(6 * i)) *= coefficient(static_cast<Eigen::Index>(i));
    }
    sigma.push_back(std::sqrt(static_cast<double>(h * covariance * h.transpose())));
  }
  return sigma;
}

// Three passes over a seabed (out, back beside it, out again over the first), a random joint
// covariance, points in two tiles each seen from poses of two or three passes (runs of pose
// indices that are not consecutive): every sigma as the formula gives it directly.
TEST(TileRelativePoseSigmas, ManyPassesGiveWhatTheFormulaGivesDirectly) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Survey survey;
  survey.name = "three passes";
  survey.kind = SurveyKind::kMap;
  for (int pass = 0; pass < 3; ++pass) {
    for (int k = 0; k < 8; ++k) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      const double along = pass == 1 ? 0.25 * (7 - k) : 0.25 * k;
      T.translation() << along, pass == 1 ? 0.3 : 0.02 * pass, 0.0;
      survey.poses.push_back(T);
    }
  }
  const auto n = static_cast<Eigen::Index>(survey.poses.size());
  Eigen::MatrixXd root(6 * n, 6 * n);
  for (Eigen::Index r = 0; r < root.rows(); ++r)
    for (Eigen::Index c = 0; c < root.cols(); ++c) root(r, c) = 0.01 * uniform(random);
  const Eigen::MatrixXd covariance =
      root * root.transpose() + 1e-6 * Eigen::MatrixXd::Identity(6 * n, 6 * n);
  std::vector<int> columns;
  for (int i = 0; i < n; ++i) columns.push_back(6 * i);
  survey.joint_uncertainty = std::make_shared<const JointPoseUncertainty>(
      Eigen::MatrixXd(covariance.inverse()).sparseView(), columns);
  std::vector<Eigen::Vector3d> points, normals;
  std::vector<long> tile_of;
  for (int k = 0; k < 30; ++k) {
    points.emplace_back(0.06 * k, 0.15 + 0.1 * uniform(random), 1.0);
    normals.push_back(
        Eigen::Vector3d(0.2 * uniform(random), 0.2 * uniform(random), -1.0).normalized());
    tile_of.push_back(k < 15 ? 4 : 9);
  }
  const std::vector<double> expected =
      DirectSigmas(survey.poses, covariance, points, normals, tile_of, 0.12);
  const std::vector<double> sigma = TileRelativePoseSigmas(survey, points, normals, tile_of, 0.12);
  ASSERT_EQ(sigma.size(), expected.size());
  for (std::size_t c = 0; c < sigma.size(); ++c) {
    EXPECT_GT(expected[c], 1e-4) << "point " << c << " tests nothing";
    EXPECT_NEAR(sigma[c], expected[c], 1e-9 * (1.0 + expected[c])) << "point " << c;
  }
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
