#include "perception/registration/svd_alignment.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

Eigen::Vector3d RandomVector(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Eigen::Vector3d{normal(rng), normal(rng), normal(rng)};
}

Eigen::Isometry3d RandomPose(std::mt19937_64& rng, double translation_scale_m) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond{normal(rng), normal(rng), normal(rng), normal(rng)}
                   .normalized()
                   .toRotationMatrix();
  T.translation() = translation_scale_m * RandomVector(rng);
  return T;
}

double RotationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

std::vector<Eigen::Vector3d> Moved(const Eigen::Isometry3d& T,
                                   const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : points) out.push_back(T * p);
  return out;
}

TEST(SvdAlignment, RecoversRandomTransforms) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Isometry3d truth = RandomPose(rng, 2.0);
    std::vector<Eigen::Vector3d> source;
    const int n = 3 + trial;
    for (int i = 0; i < n; ++i) source.push_back(0.5 * RandomVector(rng));
    const SvdAlignment fit = AlignSvd(source, Moved(truth, source));
    ASSERT_EQ(fit.status, SvdAlignmentStatus::kSuccess) << "trial " << trial;
    EXPECT_LT(RotationError(fit.T_target_source, truth), 1e-12) << "trial " << trial;
    EXPECT_LT((fit.T_target_source.translation() - truth.translation()).norm(), 1e-12);
    EXPECT_LT(fit.rmse_m, 1e-12);
    EXPECT_NEAR(fit.T_target_source.linear().determinant(), 1.0, 1e-12);
  }
}

TEST(SvdAlignment, CoplanarPointsAreEnough) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> uniform(-0.5, 0.5);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Isometry3d truth = RandomPose(rng, 1.0);
    // A random plane through a random point; 3 to 12 points on it.
    const Eigen::Isometry3d plane = RandomPose(rng, 1.0);
    std::vector<Eigen::Vector3d> source;
    for (int i = 0; i < 3 + trial % 10; ++i) {
      source.push_back(plane * Eigen::Vector3d{uniform(rng), uniform(rng), 0.0});
    }
    const SvdAlignment fit = AlignSvd(source, Moved(truth, source));
    ASSERT_EQ(fit.status, SvdAlignmentStatus::kSuccess) << "trial " << trial;
    EXPECT_LT(RotationError(fit.T_target_source, truth), 1e-12) << "trial " << trial;
    EXPECT_LT((fit.T_target_source.translation() - truth.translation()).norm(), 1e-12);
    EXPECT_NEAR(fit.T_target_source.linear().determinant(), 1.0, 1e-12);
  }
}

// Points 1e6 m from the origin, 1 m across: the coordinates themselves carry ~1e-10 m of
// rounding, so the rotation is good to ~1e-10 rad and the translation (1e6 m) to ~1e-9 m.
TEST(SvdAlignment, PointsFarFromTheOrigin) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d far(1e6, -2e6, 5e5);
    Eigen::Isometry3d truth = RandomPose(rng, 1.0);
    truth.translation() += far - truth.linear() * far;  // keeps the points near `far`
    std::vector<Eigen::Vector3d> source;
    for (int i = 0; i < 10; ++i) source.push_back(far + 0.5 * RandomVector(rng));
    const SvdAlignment fit = AlignSvd(source, Moved(truth, source));
    ASSERT_EQ(fit.status, SvdAlignmentStatus::kSuccess);
    EXPECT_LT(RotationError(fit.T_target_source, truth), 1e-9);
    for (const Eigen::Vector3d& s : source) {
      EXPECT_LT((fit.T_target_source * s - truth * s).norm(), 1e-8);
    }
  }
}

TEST(SvdAlignment, MirroredDataGivesAProperRotation) {
  std::mt19937_64 rng(4);
  const Eigen::Matrix3d mirror = Eigen::Vector3d(-1.0, 1.0, 1.0).asDiagonal();
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector3d> source, target;
    for (int i = 0; i < 20; ++i) {
      source.push_back(RandomVector(rng));
      target.push_back(mirror * source.back());
    }
    const SvdAlignment fit = AlignSvd(source, target);
    ASSERT_EQ(fit.status, SvdAlignmentStatus::kSuccess);
    const Eigen::Matrix3d R = fit.T_target_source.linear();
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    // Not an exact fit: no rotation reproduces a reflection of non-planar points.
    EXPECT_GT(fit.rmse_m, 0.1);
  }
}

// A reflection within the plane of coplanar points is a rotation by pi in 3-D: found exactly.
TEST(SvdAlignment, ReflectionOfCoplanarPointsIsARotation) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Eigen::Vector3d> source, target;
  for (int i = 0; i < 8; ++i) {
    source.push_back({uniform(rng), uniform(rng), 0.0});
    target.emplace_back(-source.back().x(), source.back().y(), 0.0);
  }
  const SvdAlignment fit = AlignSvd(source, target);
  ASSERT_EQ(fit.status, SvdAlignmentStatus::kSuccess);
  EXPECT_NEAR(fit.T_target_source.linear().determinant(), 1.0, 1e-12);
  EXPECT_LT(fit.rmse_m, 1e-12);
  const Eigen::Matrix3d expected = Eigen::Vector3d(-1.0, 1.0, -1.0).asDiagonal();
  EXPECT_LT((fit.T_target_source.linear() - expected).norm(), 1e-12);
}

TEST(SvdAlignment, DegenerateInputsAreReported) {
  const auto status = [](const std::vector<Eigen::Vector3d>& s,
                         const std::vector<Eigen::Vector3d>& t) { return AlignSvd(s, t).status; };
  const std::vector<Eigen::Vector3d> none;
  EXPECT_EQ(status(none, none), SvdAlignmentStatus::kDegenerate);
  const std::vector<Eigen::Vector3d> one = {{1, 2, 3}};
  EXPECT_EQ(status(one, one), SvdAlignmentStatus::kDegenerate);
  const std::vector<Eigen::Vector3d> two = {{1, 2, 3}, {2, 2, 3}};
  EXPECT_EQ(status(two, two), SvdAlignmentStatus::kDegenerate);
  const std::vector<Eigen::Vector3d> same = {{1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}};
  EXPECT_EQ(status(same, same), SvdAlignmentStatus::kDegenerate);

  std::mt19937_64 rng(6);
  const Eigen::Isometry3d truth = RandomPose(rng, 1.0);
  for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1e6, 2e6, 0)}) {
    const Eigen::Vector3d direction = RandomVector(rng).normalized();
    std::vector<Eigen::Vector3d> line;
    for (int i = 0; i < 10; ++i) line.push_back(offset + 0.1 * i * direction);
    EXPECT_EQ(status(line, Moved(truth, line)), SvdAlignmentStatus::kDegenerate)
        << "offset " << offset.transpose();
    const SvdAlignment fit = AlignSvd(line, Moved(truth, line));
    EXPECT_TRUE(fit.T_target_source.isApprox(Eigen::Isometry3d::Identity()));
  }
}

TEST(SvdAlignment, WeightsActLikeRepeatedPairsAndZeroWeightsAreIgnored) {
  std::mt19937_64 rng(7);
  const Eigen::Isometry3d truth = RandomPose(rng, 1.0);
  std::vector<Eigen::Vector3d> source, target;
  for (int i = 0; i < 6; ++i) {
    source.push_back(RandomVector(rng));
    target.push_back(truth * source.back() + 0.01 * RandomVector(rng));  // noisy
  }
  std::vector<double> weights = {1, 2, 1, 3, 1, 1};
  std::vector<Eigen::Vector3d> source_repeated, target_repeated;
  for (std::size_t i = 0; i < source.size(); ++i) {
    for (int r = 0; r < static_cast<int>(weights[i]); ++r) {
      source_repeated.push_back(source[i]);
      target_repeated.push_back(target[i]);
    }
  }
  const SvdAlignment weighted = AlignSvd(source, target, weights);
  const SvdAlignment repeated = AlignSvd(source_repeated, target_repeated);
  EXPECT_LT(RotationError(weighted.T_target_source, repeated.T_target_source), 1e-12);
  EXPECT_LT(
      (weighted.T_target_source.translation() - repeated.T_target_source.translation()).norm(),
      1e-12);
  EXPECT_NEAR(weighted.rmse_m, repeated.rmse_m, 1e-12);

  // A wild pair with weight 0 changes nothing.
  std::vector<Eigen::Vector3d> source_wild = source, target_wild = target;
  source_wild.emplace_back(10, 10, 10);
  target_wild.emplace_back(-50, 3, 7);
  weights.push_back(0.0);
  const SvdAlignment wild = AlignSvd(source_wild, target_wild, weights);
  EXPECT_LT(RotationError(wild.T_target_source, weighted.T_target_source), 1e-12);
  EXPECT_NEAR(wild.rmse_m, weighted.rmse_m, 1e-12);

  // Fewer than 3 positive weights is degenerate.
  EXPECT_EQ(AlignSvd(source, target, std::vector<double>{1, 1, 0, 0, 0, 0}).status,
            SvdAlignmentStatus::kDegenerate);
}

// The closed form is the least-squares optimum: any small perturbation of it costs more.
TEST(SvdAlignment, IsALeastSquaresMinimumOnNoisyData) {
  std::mt19937_64 rng(8);
  const Eigen::Isometry3d truth = RandomPose(rng, 1.0);
  std::vector<Eigen::Vector3d> source, target;
  for (int i = 0; i < 30; ++i) {
    source.push_back(RandomVector(rng));
    target.push_back(truth * source.back() + 0.05 * RandomVector(rng));
  }
  const SvdAlignment fit = AlignSvd(source, target);
  const auto cost = [&](const Eigen::Isometry3d& T) {
    double sum = 0.0;
    for (std::size_t i = 0; i < source.size(); ++i)
      sum += (T * source[i] - target[i]).squaredNorm();
    return sum;
  };
  const double best = cost(fit.T_target_source);
  EXPECT_NEAR(std::sqrt(best / 30.0), fit.rmse_m, 1e-12);
  for (int k = 0; k < 100; ++k) {
    Eigen::Isometry3d perturbed = fit.T_target_source;
    const Eigen::Vector3d w = 1e-3 * RandomVector(rng);
    perturbed.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()) * perturbed.linear();
    perturbed.translation() += 1e-3 * RandomVector(rng);
    EXPECT_GT(cost(perturbed), best);
  }
}

TEST(SvdAlignment, BadInputThrows) {
  const std::vector<Eigen::Vector3d> three = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(AlignSvd(three, two), Error);
  EXPECT_THROW(AlignSvd(three, three, std::vector<double>{1, 1}), Error);
  EXPECT_THROW(AlignSvd(three, three, std::vector<double>{1, -1, 1}), Error);
  EXPECT_THROW(AlignSvd(three, three, std::vector<double>{1, std::nan(""), 1}), Error);
  std::vector<Eigen::Vector3d> with_nan = three;
  with_nan[1].y() = std::numeric_limits<double>::quiet_NaN();
  try {
    AlignSvd(with_nan, three);
    FAIL() << "expected uwscan::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("pair 1"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace uwscan::perception
