#include "mapping/slam/overlap_gate.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace uwscan::mapping {
namespace {

// The smallest (y - gap)^T C^-1 (y - gap) over points y on the sphere of radius r, by trying
// directions on a fine grid: the brute-force reference.
double BruteForce(const Eigen::Vector3d& gap, double r, const Eigen::Matrix3d& C) {
  const Eigen::Matrix3d inverse = C.inverse();
  double best = std::numeric_limits<double>::infinity();
  const int n = 600;
  for (int i = 0; i <= n; ++i) {
    const double polar = std::numbers::pi * i / n;
    for (int j = 0; j < 2 * n; ++j) {
      const double azimuth = std::numbers::pi * j / n;
      const Eigen::Vector3d y =
          r * Eigen::Vector3d(std::sin(polar) * std::cos(azimuth),
                              std::sin(polar) * std::sin(azimuth), std::cos(polar));
      best = std::min(best, (y - gap).dot(inverse * (y - gap)));
    }
  }
  return std::sqrt(best);
}

TEST(MahalanobisGapToOverlap, IsTheGapBeyondTheOverlapInSigmasWhenTheUncertaintyIsRound) {
  const Eigen::Matrix3d C = Eigen::Matrix3d::Identity() * 0.02 * 0.02;
  EXPECT_NEAR(MahalanobisGapToOverlap({0.3, 0.4, 0.0}, 0.2, C), (0.5 - 0.2) / 0.02, 1e-9);
  EXPECT_EQ(MahalanobisGapToOverlap({0.1, 0.0, 0.0}, 0.2, C), 0.0);
}

TEST(MahalanobisGapToOverlap, AGapAlongTheLongAxisIsMorePlausible) {
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  C.diagonal() << 0.1 * 0.1, 0.01 * 0.01, 0.01 * 0.01;  // 10 cm along x, 1 cm across
  EXPECT_NEAR(MahalanobisGapToOverlap({0.5, 0.0, 0.0}, 0.2, C), 3.0, 1e-9);
  EXPECT_NEAR(MahalanobisGapToOverlap({0.0, 0.5, 0.0}, 0.2, C), 30.0, 1e-9);
}

TEST(MahalanobisGapToOverlap, MatchesABruteForceSearchOnRandomCases) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix3d A;
    for (int i = 0; i < 9; ++i) A(i) = 0.03 * normal(rng);
    const Eigen::Matrix3d C = A * A.transpose() + 1e-6 * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d gap{0.4 * normal(rng), 0.4 * normal(rng), 0.1 * normal(rng)};
    const double r = 0.1 + 0.05 * std::abs(normal(rng));
    if (gap.norm() <= r) continue;
    const double got = MahalanobisGapToOverlap(gap, r, C), reference = BruteForce(gap, r, C);
    // The grid can only find a larger value: the answer is the minimum, within the grid's step.
    EXPECT_LE(got, reference * (1.0 + 1e-9)) << "trial " << trial;
    EXPECT_GT(got, reference * 0.99) << "trial " << trial;
  }
}

TEST(MahalanobisGapToOverlap, ADirectionWithoutVarianceCannotCloseTheGap) {
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  C(0, 0) = C(1, 1) = 0.05 * 0.05;  // z known exactly
  EXPECT_EQ(MahalanobisGapToOverlap({0.0, 0.0, 0.5}, 0.2, C),
            std::numeric_limits<double>::infinity());
  // Within the overlap along z, the rest closes through x: (0.5 - sqrt(0.2^2 - 0.1^2)) / 0.05.
  EXPECT_NEAR(MahalanobisGapToOverlap({0.5, 0.0, 0.1}, 0.2, C), (0.5 - std::sqrt(0.03)) / 0.05,
              1e-6);
}

TEST(MahalanobisGapToOverlap, FailsClosedOnWhatIsNotANumberAndClosesAGapOfTinyVariance) {
  const double inf = std::numeric_limits<double>::infinity(),
               nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(MahalanobisGapToOverlap({0.5, 0.0, 0.0}, 0.2, Eigen::Matrix3d::Constant(nan)), inf);
  EXPECT_EQ(MahalanobisGapToOverlap({nan, 0.0, 0.0}, 0.2, Eigen::Matrix3d::Identity()), inf);
  // Variances of 1e-200 m^2 still measure: 0.3 m is 3e99 sigmas.
  const double m =
      MahalanobisGapToOverlap({0.5, 0.0, 0.0}, 0.2, Eigen::Matrix3d::Identity() * 1e-200);
  EXPECT_NEAR(m / 3e99, 1.0, 1e-9);
}

}  // namespace
}  // namespace uwscan::mapping
