#include "scanner/triangulation/cone_fit.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/random_draws.hpp"
#include "scanner/optics/ray.hpp"
#include "scanner/triangulation/light_cone.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kPi = std::numbers::pi;

Eigen::Vector3d RandomVector(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return DrawVector3(normal, rng);
}

Eigen::Isometry3d RandomPose(std::mt19937_64& rng) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = DrawRotation(rng).toRotationMatrix();
  T.translation() = 0.1 * RandomVector(rng);
  return T;
}

// Samples of a laser light surface: a known cone, points over h in [0.5, 1.5] m and a fan of
// +-0.6 rad around beta = pi/2, with the inputs FitCone gets from a scanner model: the
// central propagation direction (perturbed by ~3 deg) and an apex hint (2 cm off).
struct ConeData {
  EllipticCone truth;
  std::vector<Eigen::Vector3d> points_C;
  Eigen::Vector3d propagation_dir_C;
  Eigen::Vector3d apex_hint_C;
};

ConeData MakeConeData(double a, double b, int n, double sigma_m, std::uint64_t seed,
                      double dir_error = 0.05, double apex_error_m = 0.02) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, sigma_m);
  ConeData data;
  data.truth.T_C_Q = RandomPose(rng);
  data.truth.a = a;
  data.truth.b = b;
  data.truth.beta_min_rad = kPi / 2 - 0.6;
  data.truth.beta_max_rad = kPi / 2 + 0.6;
  for (int i = 0; i < n; ++i) {
    const double h = 0.5 + unit(rng);
    const double beta = data.truth.beta_min_rad + 1.2 * unit(rng);
    const Eigen::Vector3d jitter = DrawVector3(noise, rng);
    data.points_C.push_back(data.truth.Point(h, beta) + jitter);
  }
  const Eigen::Vector3d central_Q = Eigen::Vector3d(0.0, b, 1.0).normalized();
  data.propagation_dir_C =
      (data.truth.T_C_Q.linear() * central_Q + dir_error * RandomVector(rng).normalized())
          .normalized();
  data.apex_hint_C = data.truth.T_C_Q.translation() + apex_error_m * RandomVector(rng);
  return data;
}

// Largest distance between the hits of the true and the fitted cone for rays that enter the
// true cone's lit part, inside the sampled region, from outside (see light_cone_test.cpp).
double MaxHitDifference(const EllipticCone& truth, const EllipticCone& fitted, int n_rays,
                        std::uint64_t seed, int* misses) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const PreparedCone prepared_truth = PrepareCone(truth);
  const PreparedCone prepared_fit = PrepareCone(fitted);
  const double a = truth.a;
  const double b = truth.b == 0.0 ? 1e-300 : truth.b;
  double worst = 0.0;
  *misses = 0;
  for (int i = 0; i < n_rays; ++i) {
    const double h = 0.6 + 0.8 * unit(rng);
    const double beta = kPi / 2 - 0.5 + unit(rng);
    const Eigen::Vector3d p_Q(a * h * std::cos(beta), truth.b * h * std::sin(beta), h);
    // Outward normal of the multiplied-through form b^2 x^2 + a^2 y^2 - a^2 b^2 z^2 (finite
    // for b = 0), tilted by a random tangent direction.
    const Eigen::Vector3d n_Q =
        Eigen::Vector3d(b * b * p_Q.x(), a * a * p_Q.y(), -a * a * b * b * p_Q.z()).normalized();
    Eigen::Vector3d tangent = RandomVector(rng);
    tangent = (tangent - tangent.dot(n_Q) * n_Q).normalized();
    const Eigen::Vector3d w_Q = (n_Q + 0.5 * tangent).normalized();
    const Ray ray{truth.T_C_Q * (p_Q + 0.7 * w_Q), -(truth.T_C_Q.linear() * w_Q)};
    const RayHit hit_truth = IntersectRayCone(ray, prepared_truth);
    const RayHit hit_fit = IntersectRayCone(ray, prepared_fit);
    if (!hit_truth.ok() || !hit_fit.ok()) {
      ++*misses;
      continue;
    }
    worst = std::max(worst, (hit_truth.point - hit_fit.point).norm());
  }
  return worst;
}

// Both starts: the seed paper's plane start (perturbed: apex hint and propagation direction are
// off) and the algebraic quadric start, which is exact on exact cone data.
class FitConeStart : public ::testing::TestWithParam<bool> {
 protected:
  static ConeFitOptions Options() {
    ConeFitOptions options;
    options.algebraic_start = GetParam();
    return options;
  }
};

TEST_P(FitConeStart, RecoversExactCone) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    const ConeData data = MakeConeData(0.6, 0.05, 175, 0.0, seed);
    const ConeFit fit = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, Options());
    EXPECT_TRUE(fit.converged) << "seed " << seed;
    EXPECT_LT(fit.rms_m, 1e-9) << "seed " << seed;
    EXPECT_LT(fit.max_abs_m, 1e-8) << "seed " << seed;
    EXPECT_GT(fit.cone.a, 0.0);
    // The cone is the same surface whether b or its frame's x and y axes are flipped.
    EXPECT_NEAR(fit.cone.a, 0.6, 1e-6) << "seed " << seed;
    EXPECT_NEAR(std::abs(fit.cone.b), 0.05, 1e-6) << "seed " << seed;
    EXPECT_LT((fit.cone.T_C_Q.translation() - data.truth.T_C_Q.translation()).norm(), 1e-6);
    EXPECT_EQ(fit.cone.h_min_m, 0.0);
    EXPECT_GE(fit.cone.beta_min_rad, 0.0);
    EXPECT_LE(fit.cone.beta_max_rad, kPi);
    EXPECT_NO_THROW(fit.cone.Check());
    int misses = 0;
    EXPECT_LT(MaxHitDifference(data.truth, fit.cone, 300, seed + 100, &misses), 1e-8);
    EXPECT_EQ(misses, 0);
  }
}

TEST(FitCone, LitRangeIsFittedBetaRangeWidenedByMargin) {
  const ConeData data = MakeConeData(0.6, 0.05, 175, 0.0, 4);
  ConeFitOptions options;
  options.beta_margin_rad = 0.0;
  const ConeFit tight = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, options);
  options.beta_margin_rad = 0.1;
  const ConeFit wide = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, options);
  // The sampled fan is pi/2 +- 0.6 wide (up to sampling): the fitted range, in the fitted
  // cone's own beta, has the same width.
  const double width = tight.cone.beta_max_rad - tight.cone.beta_min_rad;
  EXPECT_GT(width, 1.1);
  EXPECT_LE(width, 1.2 + 1e-9);
  EXPECT_NEAR(wide.cone.beta_min_rad, tight.cone.beta_min_rad - 0.1, 1e-9);
  EXPECT_NEAR(wide.cone.beta_max_rad, tight.cone.beta_max_rad + 0.1, 1e-9);
  // Every sample lies within the lit part of the tight fit: rays onto them hit it.
  options.beta_margin_rad = 0.5;
  const ConeFit clamped = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, options);
  EXPECT_GE(clamped.cone.beta_min_rad, 0.0);
  EXPECT_LE(clamped.cone.beta_max_rad, kPi);
}

TEST_P(FitConeStart, PlanarDataGivesFlatCone) {
  const ConeData data = MakeConeData(0.6, 0.0, 175, 0.0, 5);
  const ConeFit fit = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, Options());
  EXPECT_LT(std::abs(fit.cone.b), 1e-6);
  EXPECT_LT(fit.rms_m, 1e-9);
  int misses = 0;
  // The apex and a of a flat fan are not determined by its points (a gauge freedom), but
  // the surface through them is.
  EXPECT_LT(MaxHitDifference(data.truth, fit.cone, 300, 105, &misses), 1e-8);
  EXPECT_EQ(misses, 0);
}

TEST_P(FitConeStart, NoisyDataRmsMatchesSigma) {
  const double sigma_m = 2e-4;
  const ConeData data = MakeConeData(0.6, 0.05, 1000, sigma_m, 6);
  const ConeFit fit = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, Options());
  EXPECT_TRUE(fit.converged);
  // Only the normal component of isotropic noise remains: rms ~ sigma (1 +- 1/sqrt(2n)),
  // minus the 8 + 2n of 3n degrees of freedom the fit absorbs along the surface.
  EXPECT_NEAR(fit.rms_m, sigma_m, 0.1 * sigma_m);
  EXPECT_GT(fit.max_abs_m, 2.0 * sigma_m);
  // A +-0.6 rad fan determines a and b only together (they move the surface little): over 40
  // noise draws their spread was 0.026 and 0.0047, so each is checked within 4 of those. The
  // surface itself is determined far better than the points' noise.
  EXPECT_NEAR(fit.cone.a, 0.6, 0.1);
  EXPECT_NEAR(std::abs(fit.cone.b), 0.05, 0.019);
  int misses = 0;
  EXPECT_LT(MaxHitDifference(data.truth, fit.cone, 300, 106, &misses), 0.5 * sigma_m);
  EXPECT_EQ(misses, 0);
}

TEST_P(FitConeStart, StartFarFromOptimumStillConverges) {
  // Apex hint 10 cm off and propagation direction ~17 deg off.
  const ConeData data = MakeConeData(0.6, 0.05, 175, 0.0, 7, 0.3, 0.1);
  const ConeFit fit = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, Options());
  EXPECT_TRUE(fit.converged);
  EXPECT_LT(fit.rms_m, 1e-9);
  int misses = 0;
  EXPECT_LT(MaxHitDifference(data.truth, fit.cone, 300, 107, &misses), 1e-8);
  EXPECT_EQ(misses, 0);
}

INSTANTIATE_TEST_SUITE_P(FitCone, FitConeStart, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return std::string(info.param ? "AlgebraicStart" : "PlaneStart");
                         });

// A laser fan behind a flat viewport, refracted by Snell's law (air 1.0 -> water 1.33): the
// light surface the cone model stands for, which is not exactly a cone. The mirror is at
// (0.3, 0, 0), the interface is z = 0.05, the fan spans +-0.45 rad along y and is steered by
// `steer_rad` about y; points at depths 0.4 ... 1.6 m, 35 rays x 5.
struct RefractedFan {
  std::vector<Eigen::Vector3d> points_C;
  Eigen::Vector3d central_dir_C;
  Eigen::Vector3d mirror_C{0.3, 0.0, 0.0};
};

RefractedFan MakeRefractedFan(double steer_rad) {
  RefractedFan fan;
  const Eigen::Vector3d d0(std::sin(steer_rad), 0.0, std::cos(steer_rad));
  const auto refract = [](const Eigen::Vector3d& d) {
    const Eigen::Vector2d tangential = d.head<2>() / 1.33;
    return Eigen::Vector3d(tangential.x(), tangential.y(),
                           std::sqrt(1.0 - tangential.squaredNorm()));
  };
  for (int i = 0; i < 35; ++i) {
    const double fan_angle = -0.45 + 0.9 * i / 34.0;
    const Eigen::Vector3d d =
        std::cos(fan_angle) * d0 + std::sin(fan_angle) * Eigen::Vector3d::UnitY();
    const Eigen::Vector3d on_interface = fan.mirror_C + (0.05 - fan.mirror_C.z()) / d.z() * d;
    const Eigen::Vector3d d_water = refract(d);
    if (i == 17) {
      fan.central_dir_C = d_water;
    }
    for (int j = 0; j < 5; ++j) {
      const double depth_m = 0.4 + 0.3 * j;
      fan.points_C.push_back(on_interface + (depth_m - on_interface.z()) / d_water.z() * d_water);
    }
  }
  return fan;
}

TEST(FitCone, RefractedFanFromAlgebraicStartConvergesToThePlaneStartsOptimum) {
  for (const double steer_rad : {0.3, -0.6}) {
    const RefractedFan fan = MakeRefractedFan(steer_rad);
    const PlaneFit plane = FitPlane(fan.points_C);
    const ConeFit fit = FitCone(fan.points_C, fan.central_dir_C, fan.mirror_C);
    ConeFitOptions slow;
    slow.algebraic_start = false;
    slow.max_iterations = 5000;
    const ConeFit reference = FitCone(fan.points_C, fan.central_dir_C, fan.mirror_C, slow);
    ASSERT_TRUE(fit.converged) << steer_rad;
    ASSERT_TRUE(reference.converged) << steer_rad;
    EXPECT_GT(plane.rms_m, 1e-3) << steer_rad;  // the fan visibly bends
    EXPECT_LT(fit.rms_m, 0.02 * plane.rms_m) << steer_rad;
    EXPECT_NEAR(fit.rms_m, reference.rms_m, 1e-6 * reference.rms_m) << steer_rad;
    EXPECT_LT(fit.iterations, reference.iterations) << steer_rad;
    // Same surface: rays from the camera centre through the samples hit both cones alike.
    const PreparedCone a = PrepareCone(fit.cone);
    const PreparedCone b = PrepareCone(reference.cone);
    for (const Eigen::Vector3d& p : fan.points_C) {
      const Ray ray{Eigen::Vector3d::Zero(), p.normalized()};
      const RayHit hit_a = IntersectRayCone(ray, a);
      const RayHit hit_b = IntersectRayCone(ray, b);
      ASSERT_TRUE(hit_a.ok() && hit_b.ok());
      EXPECT_LT((hit_a.point - hit_b.point).norm(), 1e-7);
    }
  }
}

TEST(FitCone, InvariantUnderRigidMotionOfTheInput) {
  const ConeData data = MakeConeData(0.6, 0.05, 175, 1e-4, 8);
  std::mt19937_64 rng(9);
  const Eigen::Isometry3d G = RandomPose(rng);
  std::vector<Eigen::Vector3d> moved;
  for (const Eigen::Vector3d& p : data.points_C) {
    moved.push_back(G * p);
  }
  const ConeFit fit = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C);
  const ConeFit fit_moved =
      FitCone(moved, G.linear() * data.propagation_dir_C, G * data.apex_hint_C);
  EXPECT_NEAR(fit_moved.rms_m, fit.rms_m, 1e-9);
  EXPECT_NEAR(fit_moved.cone.a, fit.cone.a, 1e-6);
  EXPECT_NEAR(std::abs(fit_moved.cone.b), std::abs(fit.cone.b), 1e-6);
  EXPECT_LT(((G * fit.cone.T_C_Q).translation() - fit_moved.cone.T_C_Q.translation()).norm(), 1e-6);
}

TEST(FitCone, DeterministicForSameInput) {
  const ConeData data = MakeConeData(0.6, 0.05, 300, 1e-4, 10);
  const ConeFit first = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C);
  const ConeFit second = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C);
  EXPECT_EQ(first.rms_m, second.rms_m);
  EXPECT_EQ(first.iterations, second.iterations);
  EXPECT_EQ(first.cone.a, second.cone.a);
  EXPECT_EQ(first.cone.b, second.cone.b);
  EXPECT_EQ(first.cone.T_C_Q.matrix(), second.cone.T_C_Q.matrix());
}

TEST(FitCone, IterationLimitIsReportedNotThrown) {
  const ConeData data = MakeConeData(0.6, 0.05, 175, 0.0, 11, 0.3, 0.1);
  ConeFitOptions options;
  options.max_iterations = 1;
  options.algebraic_start = false;  // the other start is exact on exact data
  ConeFit fit;
  ASSERT_NO_THROW(fit = FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, options));
  EXPECT_FALSE(fit.converged);
  EXPECT_LE(fit.iterations, 1);
  EXPECT_TRUE(std::isfinite(fit.rms_m));
  EXPECT_GT(fit.rms_m, 1e-6);
}

TEST(FitCone, ThrowsOnBadInput) {
  const ConeData data = MakeConeData(0.6, 0.05, 20, 0.0, 12);
  const auto fit = [&](const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& dir,
                       const Eigen::Vector3d& apex) { return FitCone(points, dir, apex); };
  const std::vector<Eigen::Vector3d> five(data.points_C.begin(), data.points_C.begin() + 5);
  EXPECT_THROW(fit(five, data.propagation_dir_C, data.apex_hint_C), Error);
  std::vector<Eigen::Vector3d> with_nan = data.points_C;
  with_nan[7].z() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(fit(with_nan, data.propagation_dir_C, data.apex_hint_C), Error);
  const Eigen::Vector3d nan_vector = Eigen::Vector3d::Constant(std::nan(""));
  EXPECT_THROW(fit(data.points_C, nan_vector, data.apex_hint_C), Error);
  EXPECT_THROW(fit(data.points_C, data.propagation_dir_C, nan_vector), Error);
  EXPECT_THROW(fit(data.points_C, Eigen::Vector3d::Zero(), data.apex_hint_C), Error);
  // Propagation along the normal of the points' plane: no axis in the plane.
  const Eigen::Vector3d normal_C = FitPlane(data.points_C).plane.normal;
  EXPECT_THROW(fit(data.points_C, normal_C, data.apex_hint_C), Error);
  // Apex hint in front of the points.
  EXPECT_THROW(
      fit(data.points_C, data.propagation_dir_C, data.apex_hint_C + 3.0 * data.propagation_dir_C),
      Error);
  // Collinear points do not span the fan's plane.
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 10; ++i) {
    line.push_back(Eigen::Vector3d(0.0, 0.0, 0.5 + 0.1 * i));
  }
  EXPECT_THROW(fit(line, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero()), Error);
}

TEST(FitCone, OptionsCheckNamesTheField) {
  const auto expect_field = [](const ConeFitOptions& options, const std::string& field) {
    try {
      options.Check();
      ADD_FAILURE() << "expected uwscan::Error for " << field;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("ConeFitOptions." + field), std::string::npos)
          << e.what();
    }
  };
  EXPECT_NO_THROW(ConeFitOptions{}.Check());
  ConeFitOptions o;
  o.max_iterations = 0;
  expect_field(o, "max_iterations");
  o = {};
  o.function_tolerance = -1.0;
  expect_field(o, "function_tolerance");
  o = {};
  o.parameter_tolerance = std::numeric_limits<double>::quiet_NaN();
  expect_field(o, "parameter_tolerance");
  o = {};
  o.beta_margin_rad = -0.01;
  expect_field(o, "beta_margin_rad");
  // FitCone checks its options before anything else.
  const ConeData data = MakeConeData(0.6, 0.05, 20, 0.0, 13);
  o = {};
  o.max_iterations = -3;
  EXPECT_THROW(FitCone(data.points_C, data.propagation_dir_C, data.apex_hint_C, o), Error);
}

}  // namespace
}  // namespace uwscan::scanner
