#include "perception/registration/coarse_alignment.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

FpfhDescriptor RandomDescriptor(std::mt19937_64& rng) {
  // Histogram-like: non-negative bins, each of the three 11-bin parts summing to 100.
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  FpfhDescriptor d;
  for (int i = 0; i < 33; ++i) d(i) = uniform(rng);
  for (int part = 0; part < 3; ++part)
    d.segment<11>(11 * part) *= 100.0f / d.segment<11>(11 * part).sum();
  return d;
}

FpfhDescriptor Perturbed(const FpfhDescriptor& d, float sigma, std::mt19937_64& rng) {
  std::normal_distribution<float> noise(0.0f, sigma);
  FpfhDescriptor out = d;
  for (int i = 0; i < 33; ++i) out(i) = std::max(0.0f, out(i) + noise(rng));
  return out;
}

Eigen::Isometry3d KnownMotion() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(1.1, Eigen::Vector3d(-1, 2, 0.5).normalized()).matrix();
  T.translation() = Eigen::Vector3d(0.3, -0.2, 0.15);
  return T;
}

// A synthetic keypoint matching problem. The target cloud holds 1500 random points in a 0.4 m
// box, 600 of them keypoints with random descriptors. The source cloud (in a frame moved by
// `truth`) holds `true_pairs` of those keypoints with slightly perturbed descriptors, and
// `false_pairs` keypoints at random places whose descriptors copy other target keypoints: each
// makes a correspondence that survives the mutual filter but is an outlier.
struct Problem {
  PointCloud source, target;
  FpfhFeatures source_features, target_features;
  Eigen::Isometry3d truth;  // T_target_source
};

Problem MakeProblem(int true_pairs, int false_pairs, std::uint64_t seed,
                    double position_sigma_m = 0.0,
                    const Eigen::Vector3d& target_origin = Eigen::Vector3d::Zero()) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> box(-0.2, 0.2);
  std::normal_distribution<double> noise(0.0, position_sigma_m > 0.0 ? position_sigma_m : 1.0);
  Problem problem;
  problem.truth = Eigen::Translation3d(target_origin) * KnownMotion();
  std::vector<Eigen::Vector3d> target_points;
  for (int i = 0; i < 1500; ++i)
    target_points.push_back(target_origin + Eigen::Vector3d{box(rng), box(rng), box(rng)});
  problem.target = MakeCloud(target_points);
  std::vector<std::size_t> order(target_points.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), rng);
  for (int k = 0; k < 600; ++k) {
    problem.target_features.indices.push_back(order[static_cast<std::size_t>(k)]);
    problem.target_features.descriptors.push_back(RandomDescriptor(rng));
  }
  std::vector<Eigen::Vector3d> source_points;
  const Eigen::Isometry3d T_source_target = problem.truth.inverse();
  for (int k = 0; k < true_pairs + false_pairs; ++k) {
    const std::size_t target_index = problem.target_features.indices[static_cast<std::size_t>(k)];
    const bool true_pair = k < true_pairs;
    Eigen::Vector3d p = true_pair ? T_source_target * target_points[target_index]
                                  : Eigen::Vector3d{box(rng), box(rng), box(rng)};
    if (position_sigma_m > 0.0)
      p += position_sigma_m * Eigen::Vector3d{noise(rng), noise(rng), noise(rng)};
    source_points.push_back(p);
    problem.source_features.descriptors.push_back(
        Perturbed(problem.target_features.descriptors[static_cast<std::size_t>(k)], 0.5f, rng));
  }
  // Unmatched source points around them, so feature indices are not 0..n-1.
  for (int i = 0; i < 300; ++i) source_points.push_back({box(rng), box(rng), box(rng)});
  std::vector<std::size_t> source_order(source_points.size());
  std::iota(source_order.begin(), source_order.end(), std::size_t{0});
  std::shuffle(source_order.begin(), source_order.end(), rng);
  std::vector<Eigen::Vector3d> shuffled(source_points.size());
  for (std::size_t i = 0; i < source_points.size(); ++i)
    shuffled[source_order[i]] = source_points[i];
  problem.source = MakeCloud(shuffled);
  for (int k = 0; k < true_pairs + false_pairs; ++k) {
    problem.source_features.indices.push_back(source_order[static_cast<std::size_t>(k)]);
  }
  return problem;
}

double RotationErrorRad(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}
double TranslationErrorM(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}

RegistrationResult Align(const Problem& problem, const CoarseAlignmentOptions& options = {}) {
  return AlignCoarse(problem.source, problem.source_features, problem.target,
                     problem.target_features, options);
}

void ExpectIdentical(const RegistrationResult& a, const RegistrationResult& b) {
  EXPECT_TRUE(a.T_target_source.matrix() == b.T_target_source.matrix());
  EXPECT_EQ(a.fitness, b.fitness);
  EXPECT_EQ(a.inlier_rmse, b.inlier_rmse);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.converged, b.converged);
  EXPECT_TRUE(a.information == b.information);
}

TEST(CoarseAlignment, MatchFeaturesAgreesWithBruteForce) {
  std::mt19937_64 rng(1);
  FpfhFeatures source, target;
  for (int i = 0; i < 120; ++i) source.descriptors.push_back(RandomDescriptor(rng));
  for (int i = 0; i < 90; ++i) target.descriptors.push_back(RandomDescriptor(rng));
  source.indices.resize(source.descriptors.size());
  target.indices.resize(target.descriptors.size());
  const auto nearest = [](const FpfhDescriptor& query, const std::vector<FpfhDescriptor>& set,
                          int k) {
    std::vector<std::size_t> order(set.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return (set[a] - query).squaredNorm() < (set[b] - query).squaredNorm();
    });
    order.resize(static_cast<std::size_t>(k));
    return order;
  };
  for (int k : {1, 3}) {
    for (bool mutual : {false, true}) {
      std::vector<std::pair<std::size_t, std::size_t>> expected;
      for (std::size_t i = 0; i < source.descriptors.size(); ++i) {
        for (std::size_t j : nearest(source.descriptors[i], target.descriptors, k)) {
          const auto back = nearest(target.descriptors[j], source.descriptors, k);
          if (mutual && std::find(back.begin(), back.end(), i) == back.end()) continue;
          expected.emplace_back(i, j);
        }
      }
      const auto matches = MatchFeatures(source, target, k, mutual, 2);
      ASSERT_EQ(matches.size(), expected.size()) << "k " << k << " mutual " << mutual;
      for (std::size_t m = 0; m < matches.size(); ++m) {
        EXPECT_EQ(matches[m].source_feature, expected[m].first);
        EXPECT_EQ(matches[m].target_feature, expected[m].second);
        EXPECT_NEAR(
            matches[m].distance,
            (source.descriptors[expected[m].first] - target.descriptors[expected[m].second]).norm(),
            1e-3);
      }
    }
  }
}

TEST(CoarseAlignment, MatchFeaturesBreaksTiesToTheLowerIndex) {
  std::mt19937_64 rng(2);
  const FpfhDescriptor d = RandomDescriptor(rng);
  FpfhFeatures source, target;
  source.descriptors = {d};
  source.indices = {0};
  target.descriptors = {RandomDescriptor(rng), d, d};
  target.indices = {0, 1, 2};
  const auto matches = MatchFeatures(source, target, 1, false, 1);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].target_feature, 1u);
  EXPECT_EQ(matches[0].distance, 0.0f);
}

// 100 true correspondences among 400 (75 % outliers), exact positions.
TEST(CoarseAlignment, RecoversTheMotionWithManyOutliers) {
  for (const auto& [true_pairs, false_pairs] :
       {std::pair{200, 200}, std::pair{100, 300}, std::pair{60, 240}}) {
    const Problem problem = MakeProblem(true_pairs, false_pairs, 3);
    const RegistrationResult result = Align(problem);
    EXPECT_TRUE(result.converged) << true_pairs << " of " << true_pairs + false_pairs;
    EXPECT_LT(RotationErrorRad(result.T_target_source, problem.truth), 1e-6);
    EXPECT_LT(TranslationErrorM(result.T_target_source, problem.truth), 1e-6);
    EXPECT_NEAR(result.fitness,
                static_cast<double>(true_pairs) / static_cast<double>(true_pairs + false_pairs),
                0.01);
    EXPECT_LT(result.inlier_rmse, 1e-6);
    EXPECT_LT(result.iterations, 10000);  // the adaptive stop
  }
}

TEST(CoarseAlignment, RecoversTheMotionWithNoisyPositions) {
  const Problem problem = MakeProblem(120, 280, 4, 0.001);
  CoarseAlignmentOptions options;
  options.inlier_distance_m = 0.006;
  const RegistrationResult result = Align(problem, options);
  EXPECT_TRUE(result.converged);
  EXPECT_LT(RotationErrorRad(result.T_target_source, problem.truth), 0.5 * kDeg);
  EXPECT_LT(TranslationErrorM(result.T_target_source, problem.truth), 0.002);
  EXPECT_GT(result.fitness, 0.25);
  EXPECT_LT(result.inlier_rmse, 0.003);
}

TEST(CoarseAlignment, IdenticalWithOneAndTwoThreadsAndForTheSameSeed) {
  const Problem problem = MakeProblem(80, 240, 5, 0.001);
  CoarseAlignmentOptions options;
  options.confidence = 1.0;  // all hypotheses, so most blocks run on both threads
  options.max_iterations = 5000;
  options.seed = 42;
  options.threads = 1;
  const RegistrationResult one = Align(problem, options);
  options.threads = 2;
  const RegistrationResult two = Align(problem, options);
  const RegistrationResult two_again = Align(problem, options);
  EXPECT_TRUE(one.converged);
  EXPECT_EQ(one.iterations, 5000);
  ExpectIdentical(one, two);
  ExpectIdentical(two, two_again);

  options.confidence = 0.999;  // the adaptive stop too
  options.threads = 1;
  const RegistrationResult adaptive_one = Align(problem, options);
  options.threads = 2;
  ExpectIdentical(adaptive_one, Align(problem, options));

  options.seed = 7;  // another seed: another run, the same answer
  const RegistrationResult other_seed = Align(problem, options);
  EXPECT_TRUE(other_seed.converged);
  EXPECT_LT(RotationErrorRad(other_seed.T_target_source, problem.truth), 0.5 * kDeg);
}

TEST(CoarseAlignment, InvariantToARigidMotionOfBothInputs) {
  const Problem problem = MakeProblem(100, 200, 6, 0.0005);
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  M.linear() = Eigen::AngleAxisd(2.5, Eigen::Vector3d(0.4, -0.1, 0.9).normalized()).matrix();
  M.translation() = Eigen::Vector3d(-30.0, 8.0, 150.0);
  Problem moved = problem;
  moved.source = Transformed(problem.source, M);
  moved.target = Transformed(problem.target, M);
  const RegistrationResult plain = Align(problem);
  const RegistrationResult result = Align(moved);
  // Compared in the unmoved frames, so M's 150 m lever arm does not scale rounding differences.
  const Eigen::Isometry3d moved_back = M.inverse() * result.T_target_source * M;
  EXPECT_TRUE(result.converged);
  EXPECT_LT(RotationErrorRad(moved_back, plain.T_target_source), 1e-6);
  EXPECT_LT(TranslationErrorM(moved_back, plain.T_target_source), 1e-6);
  EXPECT_EQ(result.fitness, plain.fitness);
  EXPECT_NEAR(result.inlier_rmse, plain.inlier_rmse, 1e-7);
}

TEST(CoarseAlignment, HugeCoordinates) {
  const Eigen::Vector3d far(-3e6, 1e6, -2.5e3);
  const Problem small = MakeProblem(100, 300, 7, 0.0005);
  const Problem huge = MakeProblem(100, 300, 7, 0.0005, far);
  const RegistrationResult small_result = Align(small);
  const RegistrationResult huge_result = Align(huge);
  EXPECT_TRUE(huge_result.converged);
  EXPECT_LT(RotationErrorRad(huge_result.T_target_source, huge.truth), 0.1 * kDeg);
  EXPECT_LT(TranslationErrorM(huge_result.T_target_source, huge.truth), 1e-3);
  EXPECT_NEAR(RotationErrorRad(huge_result.T_target_source, huge.truth),
              RotationErrorRad(small_result.T_target_source, small.truth), 1e-6);
  EXPECT_EQ(huge_result.fitness, small_result.fitness);
}

TEST(CoarseAlignment, OnlyOutliersIsNotConverged) {
  const Problem problem = MakeProblem(0, 400, 8);
  const RegistrationResult result = Align(problem);
  EXPECT_FALSE(result.converged);
  EXPECT_LT(result.fitness, 0.05);
  EXPECT_TRUE(result.T_target_source.matrix().allFinite());
}

TEST(CoarseAlignment, TooFewFeaturesIsNotConverged) {
  Problem problem = MakeProblem(2, 0, 9);
  const RegistrationResult result = Align(problem);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 0);
  EXPECT_TRUE(result.T_target_source.isApprox(Eigen::Isometry3d::Identity()));
  problem.source_features = {};
  EXPECT_FALSE(Align(problem).converged);
}

TEST(CoarseAlignment, BadInputThrows) {
  const Problem good = MakeProblem(10, 10, 10);
  const auto message = [](const Problem& problem) -> std::string {
    try {
      Align(problem);
    } catch (const Error& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(good), "no error");
  Problem bad = good;
  bad.source_features.indices.pop_back();
  EXPECT_NE(message(bad).find("source_features"), std::string::npos);
  bad = good;
  bad.target_features.indices[3] = bad.target.size();
  EXPECT_NE(message(bad).find("target_features.indices[3]"), std::string::npos);
  bad = good;
  bad.source_features.descriptors[5](7) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(message(bad).find("source_features.descriptors[5]"), std::string::npos);
  bad = good;
  bad.target = {};
  bad.target_features = {};
  EXPECT_NE(message(bad).find("target"), std::string::npos);
  bad = good;
  bad.source.points[2].x() = std::numeric_limits<float>::infinity();
  EXPECT_NE(message(bad).find("source: point 2"), std::string::npos);
}

TEST(CoarseAlignment, OptionsCheckNamesTheField) {
  const auto message = [](const CoarseAlignmentOptions& options) -> std::string {
    try {
      options.Check();
    } catch (const Error& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(message({}), "no error");
  CoarseAlignmentOptions options;
  options.k_nearest = 0;
  EXPECT_NE(message(options).find("k_nearest"), std::string::npos);
  options = {};
  options.max_iterations = 0;
  EXPECT_NE(message(options).find("max_iterations"), std::string::npos);
  options = {};
  options.confidence = 0.0;
  EXPECT_NE(message(options).find("confidence"), std::string::npos);
  options = {};
  options.edge_similarity = 1.0;
  EXPECT_NE(message(options).find("edge_similarity"), std::string::npos);
  options = {};
  options.inlier_distance_m = 0.0;
  EXPECT_NE(message(options).find("inlier_distance_m"), std::string::npos);
  options = {};
  options.min_inlier_fraction = 1.5;
  EXPECT_NE(message(options).find("min_inlier_fraction"), std::string::npos);
  options = {};
  options.threads = -1;
  EXPECT_NE(message(options).find("threads"), std::string::npos);
}

}  // namespace
}  // namespace uwscan::perception
