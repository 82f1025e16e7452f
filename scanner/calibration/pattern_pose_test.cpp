#include "scanner/calibration/pattern_pose.hpp"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The default scanner's camera and viewport, with the viewport tilted by ~1.4 degrees so that
// nothing relies on the normal being the optical axis.
RefractiveCamera TestCamera() {
  RefractiveCamera camera = DefaultGalvoScannerModel().camera;
  camera.viewport.normal = Eigen::Vector3d(0.02, -0.015, 1.0).normalized();
  return camera;
}

PatternSpec TestPattern() {
  PatternSpec spec;
  spec.columns = 9;
  spec.rows = 6;
  spec.square_m = 0.04;
  return spec;
}

// A pattern pose whose centre is seen at pixel `centre_px`, `depth_m` along the viewport's
// normal, tilted about x_C and y_C and spun about its own normal.
Eigen::Isometry3d PoseSeenAt(const RefractiveCamera& camera, const PatternSpec& spec,
                             const Eigen::Vector2d& centre_px, double depth_m, double tilt_x_rad,
                             double tilt_y_rad, double spin_rad) {
  Eigen::Isometry3d T_C_O = Eigen::Isometry3d::Identity();
  T_C_O.linear() = (Eigen::AngleAxisd(tilt_x_rad, Eigen::Vector3d::UnitX()) *
                    Eigen::AngleAxisd(tilt_y_rad, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(spin_rad, Eigen::Vector3d::UnitZ()))
                       .toRotationMatrix();
  const Eigen::Vector3d centre_O((spec.columns - 1) * spec.square_m / 2,
                                 (spec.rows - 1) * spec.square_m / 2, 0.0);
  const RayTrace ray = camera.PixelToRayInWater(centre_px);
  EXPECT_TRUE(ray.ok());
  const Eigen::Vector3d& n = camera.viewport.normal;
  const double t = (depth_m - n.dot(ray.ray.origin)) / n.dot(ray.ray.direction);
  T_C_O.translation() = ray.ray.At(t) - T_C_O.linear() * centre_O;
  return T_C_O;
}

// Exact refractive projections of every corner, plus Gaussian noise; nullopt when a corner
// falls outside the image.
std::optional<PatternObservation> Observe(const RefractiveCamera& camera, const PatternSpec& spec,
                                          const Eigen::Isometry3d& T_C_O, double sigma_px,
                                          std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, sigma_px > 0.0 ? sigma_px : 1.0);
  PatternObservation observation;
  const std::vector<Eigen::Vector3d> points_O = spec.CornerPoints_O();
  for (std::size_t id = 0; id < points_O.size(); ++id) {
    const std::optional<Eigen::Vector2d> uv = camera.ProjectPointInWater(T_C_O * points_O[id]);
    if (!uv || !camera.camera.InImage(*uv)) return std::nullopt;
    Eigen::Vector2d jitter = Eigen::Vector2d::Zero();
    if (sigma_px > 0.0) jitter = Eigen::Vector2d{noise(rng), noise(rng)};
    observation.corner_ids.push_back(static_cast<int>(id));
    observation.corners_px.push_back(*uv + jitter);
  }
  return observation;
}

double AngleBetween(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

TEST(ProjectThroughViewport, AgreesWithProjectPointInWater) {
  const RefractiveCamera camera = TestCamera();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const FlatViewport& v = camera.viewport;
  double worst_px = 0.0;
  for (int i = 0; i < 2000; ++i) {
    // Points seen anywhere in the image (corners included), 0.1 to 3 m beyond the port.
    const Eigen::Vector2d pixel{1023.5 + 1024.0 * unit(rng), 543.5 + 544.0 * unit(rng)};
    const RayTrace ray = camera.PixelToRayInWater(pixel);
    ASSERT_TRUE(ray.ok());
    const Eigen::Vector3d p = ray.ray.At(1.55 + 1.45 * unit(rng));
    const std::optional<Eigen::Vector2d> expected = camera.ProjectPointInWater(p);
    ASSERT_TRUE(expected);
    double uv[2];
    ASSERT_TRUE(ProjectThroughViewport(camera.camera, v.normal.data(), v.distance_m, v.thickness_m,
                                       v.n_air, v.n_glass, v.n_water, p.data(), uv));
    worst_px = std::max(worst_px, (Eigen::Vector2d(uv[0], uv[1]) - *expected).norm());
  }
  EXPECT_LT(worst_px, 1e-9);
  // A point behind the outer face has no projection.
  const Eigen::Vector3d inside(0.0, 0.0, v.distance_m + 0.5 * v.thickness_m);
  double uv[2];
  EXPECT_FALSE(ProjectThroughViewport(camera.camera, v.normal.data(), v.distance_m, v.thickness_m,
                                      v.n_air, v.n_glass, v.n_water, inside.data(), uv));
}

// Derivatives by automatic differentiation against central differences of the double path,
// for every input, including a point exactly on the viewport's axis (s = u / rho is smooth).
TEST(ProjectThroughViewport, DerivativesMatchCentralDifferences) {
  using Jet = ceres::Jet<double, 10>;
  const RefractiveCamera camera = TestCamera();
  const FlatViewport& v = camera.viewport;
  const std::vector<Eigen::Vector3d> points = {Eigen::Vector3d(0.3, -0.2, 0.9),
                                               Eigen::Vector3d(-0.6, 0.4, 0.7), 1.2 * v.normal};
  for (const Eigen::Vector3d& p : points) {
    // inputs: normal (3, unconstrained here), distance, thickness, n_glass, n_water, point (3)
    std::array<double, 10> x = {v.normal.x(),  v.normal.y(), v.normal.z(), v.distance_m,
                                v.thickness_m, v.n_glass,    v.n_water,    p.x(),
                                p.y(),         p.z()};
    const auto project = [&camera, &v](const auto& in, auto* uv) {
      using T = std::decay_t<decltype(in[0])>;
      const T normal[3] = {in[0], in[1], in[2]};
      const T point[3] = {in[7], in[8], in[9]};
      return ProjectThroughViewport(camera.camera, normal, in[3], in[4], v.n_air, in[5], in[6],
                                    point, uv);
    };
    std::array<Jet, 10> jets;
    for (int k = 0; k < 10; ++k) jets[k] = Jet(x[k], k);
    Jet uv_jet[2];
    ASSERT_TRUE(project(jets, uv_jet));
    for (int k = 0; k < 10; ++k) {
      const double h = 1e-6 * std::max(1.0, std::abs(x[k]));
      std::array<double, 10> plus = x;
      std::array<double, 10> minus = x;
      plus[k] += h;
      minus[k] -= h;
      double uv_plus[2];
      double uv_minus[2];
      ASSERT_TRUE(project(plus, uv_plus));
      ASSERT_TRUE(project(minus, uv_minus));
      for (int j = 0; j < 2; ++j) {
        const double numeric = (uv_plus[j] - uv_minus[j]) / (2.0 * h);
        EXPECT_NEAR(uv_jet[j].v[k], numeric, 1e-5 * std::max(1.0, std::abs(numeric)))
            << "input " << k << " pixel coordinate " << j << " point " << p.transpose();
      }
    }
  }
}

void ExpectExactPose(const RefractiveCamera& camera, const char* label) {
  const PatternSpec spec = TestPattern();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int tested = 0;
  double worst_m = 0.0;
  double worst_rad = 0.0;
  int max_iterations = 0;
  while (tested < 30) {
    const Eigen::Vector2d centre{1024.0 + 600.0 * unit(rng), 544.0 + 300.0 * unit(rng)};
    const double distance_m = 0.9 + 0.6 * unit(rng);
    const double tilt_a = 40.0 * kDeg * unit(rng), tilt_b = 40.0 * kDeg * unit(rng);
    const Eigen::Isometry3d truth =
        PoseSeenAt(camera, spec, centre, distance_m, tilt_a, tilt_b, std::numbers::pi * unit(rng));
    const std::optional<PatternObservation> observation = Observe(camera, spec, truth, 0.0, rng);
    if (!observation) continue;
    ++tested;
    const PatternPose pose = EstimatePatternPose(camera, spec, *observation);
    EXPECT_TRUE(pose.converged);
    EXPECT_LT(pose.rms_px, 1e-9);
    worst_m = std::max(worst_m, (pose.T_C_O.translation() - truth.translation()).norm());
    worst_rad = std::max(worst_rad, AngleBetween(pose.T_C_O, truth));
    max_iterations = std::max(max_iterations, pose.iterations);
  }
  EXPECT_LT(worst_m, 1e-9);
  EXPECT_LT(worst_rad, 1e-9);
  std::printf(
      "[%s] 30 exact poses: worst translation error %.2e m, rotation %.2e rad, "
      "max %d iterations\n",
      label, worst_m, worst_rad, max_iterations);
}

TEST(EstimatePatternPose, ExactInAir) {
  RefractiveCamera camera = TestCamera();
  camera.viewport.n_glass = 1.0;
  camera.viewport.n_water = 1.0;
  ExpectExactPose(camera, "in air");
}

TEST(EstimatePatternPose, ExactInWater) { ExpectExactPose(TestCamera(), "in water"); }

TEST(EstimatePatternPose, NoisyCornersGiveAnUnbiasedPose) {
  const RefractiveCamera camera = TestCamera();
  const PatternSpec spec = TestPattern();
  std::mt19937_64 rng(5);
  const Eigen::Isometry3d truth =
      PoseSeenAt(camera, spec, Eigen::Vector2d(900.0, 600.0), 1.2, 20 * kDeg, -25 * kDeg, 0.3);
  double sum_rms = 0.0;
  Eigen::Vector3d mean_error = Eigen::Vector3d::Zero();
  const int trials = 50;
  for (int i = 0; i < trials; ++i) {
    const std::optional<PatternObservation> observation = Observe(camera, spec, truth, 0.2, rng);
    ASSERT_TRUE(observation);
    const PatternPose pose = EstimatePatternPose(camera, spec, *observation);
    EXPECT_TRUE(pose.converged);
    sum_rms += pose.rms_px;
    mean_error += pose.T_C_O.translation() - truth.translation();
    EXPECT_LT((pose.T_C_O.translation() - truth.translation()).norm(), 2e-3);
    EXPECT_LT(AngleBetween(pose.T_C_O, truth), 0.2 * kDeg);
  }
  mean_error /= trials;
  // 54 corners, 6 parameters: the rms of the 2-D residuals is sigma sqrt(2 (108 - 6) / 108)
  // ~ 0.275 px.
  EXPECT_NEAR(sum_rms / trials, 0.2 * std::sqrt(2.0 * 102.0 / 108.0), 0.01);
  EXPECT_LT(mean_error.norm(), 3e-4);
}

// Oblique views close to the port and far away, where the pinhole PnP start is worst.
TEST(EstimatePatternPose, ObliqueNearAndFar) {
  const RefractiveCamera camera = TestCamera();
  const PatternSpec spec = TestPattern();
  std::mt19937_64 rng(3);
  for (const double depth : {0.6, 2.5}) {
    for (const double tilt : {-60.0, 60.0}) {
      const Eigen::Isometry3d truth = PoseSeenAt(camera, spec, Eigen::Vector2d(1024.0, 544.0),
                                                 depth, tilt * kDeg, 10.0 * kDeg, 0.0);
      const std::optional<PatternObservation> observation = Observe(camera, spec, truth, 0.0, rng);
      ASSERT_TRUE(observation) << depth << " " << tilt;
      const PatternPose pose = EstimatePatternPose(camera, spec, *observation);
      EXPECT_LT((pose.T_C_O.translation() - truth.translation()).norm(), 1e-9)
          << depth << " " << tilt;
      EXPECT_LT(AngleBetween(pose.T_C_O, truth), 1e-9);
    }
  }
}

TEST(EstimatePatternPose, PartialViewOfFourCorners) {
  const RefractiveCamera camera = TestCamera();
  const PatternSpec spec = TestPattern();
  std::mt19937_64 rng(1);
  const Eigen::Isometry3d truth =
      PoseSeenAt(camera, spec, Eigen::Vector2d(1100.0, 500.0), 0.8, 0.3, 0.2, 0.1);
  const std::optional<PatternObservation> full = Observe(camera, spec, truth, 0.0, rng);
  ASSERT_TRUE(full);
  PatternObservation four;
  for (const int id : {0, 8, 45, 53}) {  // the four outer corners
    four.corner_ids.push_back(id);
    four.corners_px.push_back(full->corners_px[static_cast<std::size_t>(id)]);
  }
  const PatternPose pose = EstimatePatternPose(camera, spec, four);
  EXPECT_LT((pose.T_C_O.translation() - truth.translation()).norm(), 1e-8);
  EXPECT_LT(AngleBetween(pose.T_C_O, truth), 1e-8);
}

TEST(EstimatePatternPose, BadInputThrows) {
  const RefractiveCamera camera = TestCamera();
  const PatternSpec spec = TestPattern();
  std::mt19937_64 rng(2);
  const Eigen::Isometry3d truth =
      PoseSeenAt(camera, spec, Eigen::Vector2d(1024.0, 544.0), 1.0, 0.1, 0.1, 0.0);
  const std::optional<PatternObservation> good = Observe(camera, spec, truth, 0.0, rng);
  ASSERT_TRUE(good);

  PatternObservation three;
  three.image = "three.png";
  for (int id = 0; id < 3; ++id) {
    three.corner_ids.push_back(id * 10);
    three.corners_px.push_back(good->corners_px[static_cast<std::size_t>(id * 10)]);
  }
  try {
    EstimatePatternPose(camera, spec, three);
    ADD_FAILURE() << "three corners accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("three.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at least 4"), std::string::npos) << e.what();
  }

  PatternObservation row;  // the first row only: collinear
  for (int id = 0; id < 9; ++id) {
    row.corner_ids.push_back(id);
    row.corners_px.push_back(good->corners_px[static_cast<std::size_t>(id)]);
  }
  EXPECT_THROW(EstimatePatternPose(camera, spec, row), Error);

  PatternObservation nan = *good;
  nan.corners_px[7].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(EstimatePatternPose(camera, spec, nan), Error);

  PatternObservation out_of_range = *good;
  out_of_range.corner_ids[3] = 54;
  EXPECT_THROW(EstimatePatternPose(camera, spec, out_of_range), Error);

  PatternObservation repeated = *good;
  repeated.corner_ids[3] = repeated.corner_ids[4];
  EXPECT_THROW(EstimatePatternPose(camera, spec, repeated), Error);

  PatternObservation mismatched = *good;
  mismatched.corner_ids.pop_back();
  EXPECT_THROW(EstimatePatternPose(camera, spec, mismatched), Error);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
