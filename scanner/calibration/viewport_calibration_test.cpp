#include "scanner/calibration/viewport_calibration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/random_draws.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/optics/refractive_camera.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The true scanner: the default camera and camera viewport (PMMA 12 mm, 30 mm from the
// centre, n_water 1.33) with the normal tilted by ~1.4 degrees, a realistic mounting error
// that keeps the problem generic (a normal exactly on the optical axis is a special case).
RefractiveCamera TrueCamera() {
  RefractiveCamera camera = DefaultGalvoScannerModel().camera;
  camera.viewport.normal = Eigen::Vector3d(0.02, -0.015, 1.0).normalized();
  camera.viewport.n_water = 1.33;
  return camera;
}

PatternSpec TestPattern() {
  PatternSpec spec;
  spec.columns = 9;
  spec.rows = 6;
  spec.square_m = 0.04;
  return spec;
}

struct Dataset {
  std::vector<PatternObservation> observations;
  std::vector<Eigen::Isometry3d> T_C_O;
};

// `views` poses of the pattern 0.5-1.5 m away (along the normal), seen anywhere in the central
// 80 % of the image, tilted up to 35 degrees about x and y and spun freely, every corner in
// the image; corners projected exactly through the true viewport plus N(0, sigma_px^2) noise.
Dataset MakeDataset(const RefractiveCamera& camera, const PatternSpec& spec, int views,
                    double sigma_px, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  const std::vector<Eigen::Vector3d> points_O = spec.CornerPoints_O();
  const Eigen::Vector3d centre_O((spec.columns - 1) * spec.square_m / 2,
                                 (spec.rows - 1) * spec.square_m / 2, 0.0);
  Dataset data;
  while (static_cast<int>(data.observations.size()) < views) {
    const double depth = 1.0 + 0.5 * unit(rng);
    const Eigen::Vector2d centre_px =
        Eigen::Vector2d(1023.5, 543.5) +
        0.8 * Eigen::Vector2d(1024.0, 544.0).cwiseProduct(DrawVector2(unit, rng));
    const Eigen::Vector3d angles = DrawVector3(unit, rng);
    Eigen::Isometry3d T_C_O = Eigen::Isometry3d::Identity();
    T_C_O.linear() = (Eigen::AngleAxisd(35.0 * kDeg * angles.x(), Eigen::Vector3d::UnitX()) *
                      Eigen::AngleAxisd(35.0 * kDeg * angles.y(), Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(std::numbers::pi * angles.z(), Eigen::Vector3d::UnitZ()))
                         .toRotationMatrix();
    const RayTrace ray = camera.PixelToRayInWater(centre_px);
    if (!ray.ok()) continue;
    const Eigen::Vector3d& n = camera.viewport.normal;
    const double t = (depth - n.dot(ray.ray.origin)) / n.dot(ray.ray.direction);
    T_C_O.translation() = ray.ray.At(t) - T_C_O.linear() * centre_O;

    PatternObservation observation;
    observation.image = "view" + std::to_string(data.observations.size()) + ".png";
    bool inside = true;
    for (std::size_t id = 0; id < points_O.size() && inside; ++id) {
      const std::optional<Eigen::Vector2d> uv = camera.ProjectPointInWater(T_C_O * points_O[id]);
      inside = uv && camera.camera.InImage(*uv);
      if (!inside) break;
      const Eigen::Vector2d jitter = sigma_px * DrawVector2(noise, rng);
      observation.corner_ids.push_back(static_cast<int>(id));
      observation.corners_px.push_back(*uv + jitter);
    }
    if (!inside) continue;
    data.observations.push_back(std::move(observation));
    data.T_C_O.push_back(T_C_O);
  }
  return data;
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

struct TimedRun {
  ViewportCalibrationResult result;
  double seconds = 0.0;
};

TimedRun Calibrate(const RefractiveCamera& truth, const FlatViewport& initial, const Dataset& data,
                   const ViewportCalibrationOptions& options = {}) {
  const auto start = std::chrono::steady_clock::now();
  TimedRun run;
  run.result =
      CalibrateCameraViewport(truth.camera, initial, TestPattern(), data.observations, options);
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

void Print(const char* label, const FlatViewport& truth, const TimedRun& run) {
  const ViewportCalibrationResult& r = run.result;
  std::printf(
      "[%s] normal %.3e rad (std %.3e), distance %+.3e m (std %.3e), thickness %+.3e m "
      "(std %.3e), n_glass %+.3e (std %.3e), n_water %+.3e (std %.3e), corr(d,t) %+.4f, "
      "rms %.4f px, max %.4f px, %d iterations, converged %d, %.3f s\n",
      label, AngleBetween(r.viewport.normal, truth.normal), r.normal_std_rad,
      r.viewport.distance_m - truth.distance_m, r.distance_std_m,
      r.viewport.thickness_m - truth.thickness_m, r.thickness_std_m,
      r.viewport.n_glass - truth.n_glass, r.n_glass_std, r.viewport.n_water - truth.n_water,
      r.n_water_std, r.distance_thickness_correlation, r.rms_px, r.max_px, r.iterations,
      r.converged ? 1 : 0, run.seconds);
}

// The CAD start of the tests: the truth moved by `offset_m` along the normal (inner face
// offset) and the normal rotated by `angle_rad` about an axis perpendicular to it.
FlatViewport PerturbedViewport(const FlatViewport& truth, double offset_m, double angle_rad,
                               double axis_angle_rad, double thickness_offset_m = 0.0) {
  FlatViewport v = truth;
  const Eigen::Vector3d a = truth.normal.unitOrthogonal();
  const Eigen::Vector3d b = truth.normal.cross(a);
  const Eigen::Vector3d axis = std::cos(axis_angle_rad) * a + std::sin(axis_angle_rad) * b;
  v.normal = (Eigen::AngleAxisd(angle_rad, axis) * truth.normal).normalized();
  v.distance_m += offset_m;
  v.thickness_m += thickness_offset_m;
  return v;
}

TEST(CalibrateCameraViewport, ExactDataExactRecovery) {
  const RefractiveCamera truth = TrueCamera();
  const Dataset data = MakeDataset(truth, TestPattern(), 20, 0.0, 42);
  const TimedRun run =
      Calibrate(truth, PerturbedViewport(truth.viewport, 0.005, 2.0 * kDeg, 0.7), data);
  Print("exact data, poor start", truth.viewport, run);
  const ViewportCalibrationResult& r = run.result;
  EXPECT_TRUE(r.converged);
  EXPECT_LT(AngleBetween(r.viewport.normal, truth.viewport.normal), 1e-9);
  EXPECT_NEAR(r.viewport.distance_m, truth.viewport.distance_m, 1e-9);
  EXPECT_NEAR(r.viewport.thickness_m, truth.viewport.thickness_m, 1e-9);
  EXPECT_EQ(r.viewport.n_glass, truth.viewport.n_glass);  // held
  EXPECT_EQ(r.viewport.n_water, truth.viewport.n_water);
  EXPECT_LT(r.rms_px, 1e-9);
  ASSERT_EQ(r.T_C_O.size(), data.T_C_O.size());
  for (std::size_t i = 0; i < r.T_C_O.size(); ++i) {
    EXPECT_LT((r.T_C_O[i].translation() - data.T_C_O[i].translation()).norm(), 1e-9);
  }
}

TEST(CalibrateCameraViewport, NoisyDataWithinStandardDeviations) {
  const RefractiveCamera truth = TrueCamera();
  const Dataset data = MakeDataset(truth, TestPattern(), 20, 0.2, 7);
  ViewportCalibrationOptions refine_all;
  refine_all.refine_thickness = true;
  const TimedRun run = Calibrate(truth, truth.viewport, data, refine_all);
  Print("0.2 px noise, truth start", truth.viewport, run);
  const ViewportCalibrationResult& r = run.result;
  EXPECT_TRUE(r.converged);
  // 20 x 54 corners, 2 x 1080 residuals, 124 parameters: rms 0.2 sqrt(2 (2160 - 124) / 2160).
  EXPECT_NEAR(r.rms_px, 0.2 * std::sqrt(2.0 * 2036.0 / 2160.0), 0.015);
  ASSERT_TRUE(std::isfinite(r.normal_std_rad) && r.normal_std_rad > 0.0);
  ASSERT_TRUE(std::isfinite(r.distance_std_m) && r.distance_std_m > 0.0);
  ASSERT_TRUE(std::isfinite(r.thickness_std_m) && r.thickness_std_m > 0.0);
  // The normal's error has two components; its norm is compared against the larger std.
  EXPECT_LT(AngleBetween(r.viewport.normal, truth.viewport.normal), 4.0 * r.normal_std_rad);
  EXPECT_LT(std::abs(r.viewport.distance_m - truth.viewport.distance_m), 4.0 * r.distance_std_m);
  EXPECT_LT(std::abs(r.viewport.thickness_m - truth.viewport.thickness_m), 4.0 * r.thickness_std_m);
  EXPECT_EQ(r.n_glass_std, 0.0);
  EXPECT_EQ(r.n_water_std, 0.0);
  EXPECT_EQ(r.view_rms_px.size(), 20u);
  // The figures behind the degeneracy note of viewport_calibration.hpp: with the poses free,
  // distance and thickness are separated only by the non-paraxial shape of the refraction.
  EXPECT_GT(r.thickness_std_m, 0.01);
  EXPECT_GT(std::abs(r.distance_thickness_correlation), 0.99);
}

// The thickness known (measured), as recommended: normal and distance are well determined.
TEST(CalibrateCameraViewport, NoisyDataThicknessHeld) {
  const RefractiveCamera truth = TrueCamera();
  const Dataset data = MakeDataset(truth, TestPattern(), 20, 0.2, 7);
  ViewportCalibrationOptions options;
  options.refine_thickness = false;
  const TimedRun run = Calibrate(truth, truth.viewport, data, options);
  Print("0.2 px noise, thickness held, truth start", truth.viewport, run);
  const ViewportCalibrationResult& r = run.result;
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.rms_px, 0.2 * std::sqrt(2.0 * 2037.0 / 2160.0), 0.015);
  ASSERT_TRUE(std::isfinite(r.distance_std_m) && r.distance_std_m > 0.0);
  EXPECT_LT(r.distance_std_m, 2e-3);
  EXPECT_LT(r.normal_std_rad, 2e-3);
  EXPECT_EQ(r.thickness_std_m, 0.0);
  EXPECT_EQ(r.viewport.thickness_m, truth.viewport.thickness_m);
  EXPECT_LT(AngleBetween(r.viewport.normal, truth.viewport.normal), 4.0 * r.normal_std_rad);
  EXPECT_LT(std::abs(r.viewport.distance_m - truth.viewport.distance_m), 4.0 * r.distance_std_m);
}

// The standard deviations mean what they say: over independent noise draws the errors scatter
// as much as the reported standard deviations (within sampling error). Thickness held: with it
// refined, about half the draws end on its bound (thickness 0), which clips the scatter.
TEST(CalibrateCameraViewport, StandardDeviationsMatchTheScatter) {
  const RefractiveCamera truth = TrueCamera();
  ViewportCalibrationOptions options;
  options.refine_thickness = false;
  const int trials = 12;
  double sum_sq_distance = 0.0;
  double sum_sq_normal = 0.0;
  double sum_var_distance = 0.0;
  double sum_var_normal = 0.0;
  for (int k = 0; k < trials; ++k) {
    const Dataset data = MakeDataset(truth, TestPattern(), 20, 0.2, 100 + k);
    const ViewportCalibrationResult r = Calibrate(truth, truth.viewport, data, options).result;
    sum_sq_distance += std::pow(r.viewport.distance_m - truth.viewport.distance_m, 2);
    sum_sq_normal += std::pow(AngleBetween(r.viewport.normal, truth.viewport.normal), 2);
    sum_var_distance += r.distance_std_m * r.distance_std_m;
    sum_var_normal += r.normal_std_rad * r.normal_std_rad;
  }
  const double ratio_distance = std::sqrt(sum_sq_distance / sum_var_distance);
  // The normal's error has two components and normal_std_rad is the larger one's std.
  const double ratio_normal = std::sqrt(sum_sq_normal / sum_var_normal);
  std::printf(
      "[scatter over %d datasets, thickness held] rms error / rms std: distance %.2f, "
      "normal %.2f (two components against the larger: <= sqrt(2))\n",
      trials, ratio_distance, ratio_normal);
  // With 12 trials the sample rms has a relative spread of ~20 %.
  EXPECT_GT(ratio_distance, 0.5);
  EXPECT_LT(ratio_distance, 1.6);
  EXPECT_GT(ratio_normal, 0.5);
  EXPECT_LT(ratio_normal, 2.0);
}

// Required: started 5 mm and 2 degrees from the truth (in several directions, the thickness
// 3 mm off too), the fit lands on the same optimum as when started from the truth; with the
// thickness refined (the default) and held.
TEST(CalibrateCameraViewport, ConvergesFromAPoorStart) {
  const RefractiveCamera truth = TrueCamera();
  const Dataset data = MakeDataset(truth, TestPattern(), 20, 0.2, 7);
  for (const bool refine_thickness : {true, false}) {
    ViewportCalibrationOptions options;
    options.refine_thickness = refine_thickness;
    const TimedRun reference = Calibrate(truth, truth.viewport, data, options);
    Print(refine_thickness ? "from the truth, thickness refined" : "from the truth, thickness held",
          truth.viewport, reference);
    int case_index = 0;
    for (const double offset_m : {0.005, -0.005}) {
      for (const double axis_angle : {0.0, 0.5 * std::numbers::pi, 2.3, 4.0}) {
        for (const double thickness_offset_m : {0.0, 0.003}) {
          if (!refine_thickness && thickness_offset_m != 0.0) continue;
          const FlatViewport start = PerturbedViewport(truth.viewport, offset_m, 2.0 * kDeg,
                                                       axis_angle, thickness_offset_m);
          const TimedRun run = Calibrate(truth, start, data, options);
          const ViewportCalibrationResult& a = run.result;
          const ViewportCalibrationResult& b = reference.result;
          char label[160];
          std::snprintf(label, sizeof(label),
                        "poor start %d (%s): %+.0f mm, 2 deg about axis %.1f rad, thickness "
                        "%+.0f mm",
                        case_index++, refine_thickness ? "thickness refined" : "thickness held",
                        offset_m * 1e3, axis_angle, thickness_offset_m * 1e3);
          std::printf(
              "[%s] vs from-truth: normal %.2e rad, distance %.2e m, thickness %.2e m, "
              "rms %.2e px; %d iterations, %.3f s\n",
              label, AngleBetween(a.viewport.normal, b.viewport.normal),
              std::abs(a.viewport.distance_m - b.viewport.distance_m),
              std::abs(a.viewport.thickness_m - b.viewport.thickness_m),
              std::abs(a.rms_px - b.rms_px), a.iterations, run.seconds);
          // The same optimum: apart by less than 1e-5 of a standard deviation (both runs stop
          // when the cost changes by less than its round-off; exact data show 1e-13 m).
          EXPECT_TRUE(a.converged) << label;
          EXPECT_LT(AngleBetween(a.viewport.normal, b.viewport.normal), 1e-5 * b.normal_std_rad)
              << label;
          EXPECT_LT(std::abs(a.viewport.distance_m - b.viewport.distance_m),
                    1e-5 * b.distance_std_m)
              << label;
          EXPECT_LE(std::abs(a.viewport.thickness_m - b.viewport.thickness_m),
                    1e-5 * b.thickness_std_m)
              << label;
          EXPECT_NEAR(a.rms_px, b.rms_px, 1e-9) << label;
        }
      }
    }
  }
}

// With one index refined as well: still determined (finite standard deviations) and the truth
// within a few of them, from the poor start.
TEST(CalibrateCameraViewport, RefiningTheWaterIndex) {
  const RefractiveCamera truth = TrueCamera();
  const Dataset data = MakeDataset(truth, TestPattern(), 20, 0.2, 7);
  ViewportCalibrationOptions options;
  options.refine_thickness = true;
  options.refine_water_index = true;
  FlatViewport start = PerturbedViewport(truth.viewport, 0.005, 2.0 * kDeg, 0.7);
  start.n_water = 1.34;
  const TimedRun run = Calibrate(truth, start, data, options);
  Print("n_water refined too", truth.viewport, run);
  const ViewportCalibrationResult& r = run.result;
  EXPECT_TRUE(r.converged);
  ASSERT_TRUE(std::isfinite(r.n_water_std) && r.n_water_std > 0.0);
  EXPECT_LT(std::abs(r.viewport.n_water - truth.viewport.n_water), 4.0 * r.n_water_std);
  EXPECT_LT(std::abs(r.viewport.distance_m - truth.viewport.distance_m), 4.0 * r.distance_std_m);
  EXPECT_LT(std::abs(r.viewport.thickness_m - truth.viewport.thickness_m), 4.0 * r.thickness_std_m);
}

// The documented weak spot: the glass index, refined even with the thickness held, trades off
// against the distance and is not determined at all in practice.
TEST(CalibrateCameraViewport, GlassIndexIsBarelyDetermined) {
  const RefractiveCamera truth = TrueCamera();
  const Dataset data = MakeDataset(truth, TestPattern(), 20, 0.2, 7);
  ViewportCalibrationOptions options;
  options.refine_thickness = false;
  options.refine_glass_index = true;
  const TimedRun run = Calibrate(truth, truth.viewport, data, options);
  Print("n_glass refined, thickness held", truth.viewport, run);
  options.refine_glass_index = false;
  const TimedRun held = Calibrate(truth, truth.viewport, data, options);
  // The index trades against the distance: freeing it leaves the index itself undetermined
  // (std > 1) and the distance ~20 times less certain than with the index known (over 10 here;
  // the factor varies with the views drawn).
  EXPECT_GT(run.result.n_glass_std, 1.0);
  EXPECT_GT(run.result.distance_std_m, 10.0 * held.result.distance_std_m);
  EXPECT_LT(run.result.normal_std_rad, 2e-3);  // the normal is unaffected
}

TEST(CalibrateCameraViewport, BadInputThrows) {
  const RefractiveCamera truth = TrueCamera();
  const PatternSpec spec = TestPattern();
  const Dataset data = MakeDataset(truth, spec, 4, 0.0, 3);

  const std::vector<PatternObservation> two(data.observations.begin(),
                                            data.observations.begin() + 2);
  try {
    CalibrateCameraViewport(truth.camera, truth.viewport, spec, two);
    ADD_FAILURE() << "two views accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("need at least 3"), std::string::npos) << e.what();
  }

  std::vector<PatternObservation> with_nan = data.observations;
  with_nan[2].corners_px[5].y() = std::numeric_limits<double>::quiet_NaN();
  try {
    CalibrateCameraViewport(truth.camera, truth.viewport, spec, with_nan);
    ADD_FAILURE() << "NaN corner accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("view 2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }

  std::vector<PatternObservation> few_corners = data.observations;
  few_corners[1].corner_ids.resize(3);
  few_corners[1].corners_px.resize(3);
  EXPECT_THROW(CalibrateCameraViewport(truth.camera, truth.viewport, spec, few_corners), Error);

  ViewportCalibrationOptions bad_options;
  bad_options.max_iterations = 0;
  EXPECT_THROW(
      CalibrateCameraViewport(truth.camera, truth.viewport, spec, data.observations, bad_options),
      Error);

  FlatViewport outside = truth.viewport;
  outside.distance_m = -0.01;  // camera centre outside the housing
  EXPECT_THROW(CalibrateCameraViewport(truth.camera, outside, spec, data.observations), Error);

  PinholeCamera no_focal = truth.camera;
  no_focal.fx_px = 0.0;
  EXPECT_THROW(CalibrateCameraViewport(no_focal, truth.viewport, spec, data.observations), Error);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
