#include "scanner/calibration/intrinsics_calibration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

PatternSpec TestPattern() {
  PatternSpec spec;
  spec.columns = 9;
  spec.rows = 6;
  spec.square_m = 0.04;
  return spec;
}

// `views` views in air of the pattern 0.45-1.0 m away, tilted up to 40 degrees, centred
// anywhere in the image so that the corners reach the image edges (where the distortion is
// observed); every corner in the image; corners projected by `camera` plus N(0, sigma^2).
std::vector<PatternObservation> MakeViews(const PinholeCamera& camera, const PatternSpec& spec,
                                          int views, double sigma_px, std::uint64_t seed,
                                          std::vector<Eigen::Isometry3d>* poses = nullptr) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  const std::vector<Eigen::Vector3d> points_O = spec.CornerPoints_O();
  const Eigen::Vector3d centre_O((spec.columns - 1) * spec.square_m / 2,
                                 (spec.rows - 1) * spec.square_m / 2, 0.0);
  std::vector<PatternObservation> observations;
  while (static_cast<int>(observations.size()) < views) {
    Eigen::Isometry3d T_C_O = Eigen::Isometry3d::Identity();
    T_C_O.linear() = (Eigen::AngleAxisd(40.0 * kDeg * unit(rng), Eigen::Vector3d::UnitX()) *
                      Eigen::AngleAxisd(40.0 * kDeg * unit(rng), Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(std::numbers::pi * unit(rng), Eigen::Vector3d::UnitZ()))
                         .toRotationMatrix();
    const double depth = 0.725 + 0.275 * unit(rng);
    const std::optional<Eigen::Vector3d> ray = camera.BackProject(
        Eigen::Vector2d{1023.5 + 0.85 * 1024.0 * unit(rng), 543.5 + 0.85 * 544.0 * unit(rng)});
    if (!ray) continue;
    T_C_O.translation() = (depth / ray->z()) * *ray - T_C_O.linear() * centre_O;
    PatternObservation observation;
    observation.image = "air" + std::to_string(observations.size()) + ".png";
    bool inside = true;
    for (std::size_t id = 0; id < points_O.size(); ++id) {
      const Eigen::Vector3d p_C = T_C_O * points_O[id];
      const Eigen::Vector2d uv = camera.Project(p_C);
      if (!(p_C.z() > 0.0) || !camera.InImage(uv)) {
        inside = false;
        break;
      }
      observation.corner_ids.push_back(static_cast<int>(id));
      observation.corners_px.push_back(uv + sigma_px * Eigen::Vector2d{noise(rng), noise(rng)});
    }
    if (!inside) continue;
    observations.push_back(std::move(observation));
    if (poses) poses->push_back(T_C_O);
  }
  return observations;
}

void PrintResult(const char* label, const PinholeCamera& truth, const IntrinsicsResult& r,
                 double seconds) {
  const PinholeCamera& c = r.camera;
  std::printf(
      "[%s] fx %+.3f px (std %.3f), fy %+.3f (std %.3f), cx %+.3f (std %.3f), cy %+.3f "
      "(std %.3f); k1 %+.2e (std %.1e), k2 %+.2e (std %.1e), p1 %+.2e (std %.1e), p2 %+.2e "
      "(std %.1e), k3 %+.2e (std %.1e); rms %.4f px; %.3f s\n",
      label, c.fx_px - truth.fx_px, r.fx_std, c.fy_px - truth.fy_px, r.fy_std,
      c.cx_px - truth.cx_px, r.cx_std, c.cy_px - truth.cy_px, r.cy_std, c.k1 - truth.k1,
      r.distortion_std[0], c.k2 - truth.k2, r.distortion_std[1], c.p1 - truth.p1,
      r.distortion_std[2], c.p2 - truth.p2, r.distortion_std[3], c.k3 - truth.k3,
      r.distortion_std[4], r.rms_px, seconds);
}

void ExpectWithinStd(const PinholeCamera& truth, const IntrinsicsResult& r, double k) {
  const PinholeCamera& c = r.camera;
  EXPECT_LT(std::abs(c.fx_px - truth.fx_px), k * r.fx_std);
  EXPECT_LT(std::abs(c.fy_px - truth.fy_px), k * r.fy_std);
  EXPECT_LT(std::abs(c.cx_px - truth.cx_px), k * r.cx_std);
  EXPECT_LT(std::abs(c.cy_px - truth.cy_px), k * r.cy_std);
  EXPECT_LT(std::abs(c.k1 - truth.k1), k * r.distortion_std[0]);
  EXPECT_LT(std::abs(c.k2 - truth.k2), k * r.distortion_std[1]);
  EXPECT_LT(std::abs(c.p1 - truth.p1), k * r.distortion_std[2]);
  EXPECT_LT(std::abs(c.p2 - truth.p2), k * r.distortion_std[3]);
  EXPECT_LT(std::abs(c.k3 - truth.k3), k * r.distortion_std[4]);
}

TEST(CalibrateIntrinsics, RecoversTheDefaultCamera) {
  const PinholeCamera truth = DefaultGalvoScannerModel().camera.camera;
  const PatternSpec spec = TestPattern();
  std::vector<Eigen::Isometry3d> poses;
  const std::vector<PatternObservation> views = MakeViews(truth, spec, 15, 0.2, 21, &poses);
  const auto start = std::chrono::steady_clock::now();
  const IntrinsicsResult r = CalibrateIntrinsics(spec, views, truth.width_px, truth.height_px);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  PrintResult("15 views, 0.2 px", truth, r, seconds);
  EXPECT_EQ(r.camera.width_px, truth.width_px);
  EXPECT_EQ(r.camera.height_px, truth.height_px);
  ExpectWithinStd(truth, r, 4.0);
  // Finite, non-zero and a few pixels at most: a well-posed calibration.
  EXPECT_GT(r.fx_std, 0.0);
  EXPECT_LT(r.fx_std, 5.0);
  EXPECT_LT(r.cx_std, 5.0);
  // 15 x 54 corners, 1620 residuals, 9 + 90 parameters: rms 0.2 sqrt(2 (1620 - 99) / 1620).
  EXPECT_NEAR(r.rms_px, 0.2 * std::sqrt(2.0 * 1521.0 / 1620.0), 0.015);
  ASSERT_EQ(r.views.size(), 15u);
  ASSERT_EQ(r.T_C_O.size(), 15u);
  for (std::size_t i = 0; i < r.views.size(); ++i) {
    EXPECT_FALSE(r.views[i].rejected);
    EXPECT_EQ(r.views[i].image, views[i].image);
    EXPECT_LT(r.views[i].rms_px, 0.4);
    EXPECT_LT((r.T_C_O[i].translation() - poses[i].translation()).norm(), 2e-3);
  }
}

TEST(CalibrateIntrinsics, ExactCornersExactIntrinsics) {
  const PinholeCamera truth = DefaultGalvoScannerModel().camera.camera;
  const PatternSpec spec = TestPattern();
  const std::vector<PatternObservation> views = MakeViews(truth, spec, 15, 0.0, 22);
  const IntrinsicsResult r = CalibrateIntrinsics(spec, views, truth.width_px, truth.height_px);
  PrintResult("15 views, exact (float) corners", truth, r, 0.0);
  // calibrateCamera works in single precision corners: ~1e-4 px of rounding.
  EXPECT_LT(r.rms_px, 1e-3);
  EXPECT_NEAR(r.camera.fx_px, truth.fx_px, 0.01);
  EXPECT_NEAR(r.camera.cy_px, truth.cy_px, 0.01);
  EXPECT_NEAR(r.camera.k1, truth.k1, 1e-5);
}

TEST(CalibrateIntrinsics, RejectsACorruptedView) {
  const PinholeCamera truth = DefaultGalvoScannerModel().camera.camera;
  const PatternSpec spec = TestPattern();
  std::vector<PatternObservation> views = MakeViews(truth, spec, 15, 0.2, 21);
  // View 6: the last two rows shifted 4 px sideways (a uniform shift would only move the pose).
  PatternObservation& bad = views[6];
  for (std::size_t j = 0; j < bad.corner_ids.size(); ++j) {
    if (bad.corner_ids[j] >= 4 * spec.columns) bad.corners_px[j].x() += 4.0;
  }
  const IntrinsicsResult r = CalibrateIntrinsics(spec, views, truth.width_px, truth.height_px);
  PrintResult("15 views, view 6 corrupted", truth, r, 0.0);
  for (std::size_t i = 0; i < r.views.size(); ++i) {
    EXPECT_EQ(r.views[i].rejected, i == 6) << i;
  }
  EXPECT_GT(r.views[6].rms_px, 1.0);
  EXPECT_TRUE(r.T_C_O[6].isApprox(Eigen::Isometry3d::Identity()));
  ExpectWithinStd(truth, r, 4.0);
  std::printf("[corrupted view] rms of the rejected view under the final calibration %.3f px\n",
              r.views[6].rms_px);
}

TEST(CalibrateIntrinsics, FixK3) {
  const PinholeCamera truth = DefaultGalvoScannerModel().camera.camera;
  const PatternSpec spec = TestPattern();
  const std::vector<PatternObservation> views = MakeViews(truth, spec, 15, 0.2, 23);
  IntrinsicsOptions options;
  options.fix_k3 = true;
  const IntrinsicsResult r =
      CalibrateIntrinsics(spec, views, truth.width_px, truth.height_px, options);
  EXPECT_EQ(r.camera.k3, 0.0);
  EXPECT_EQ(r.distortion_std[4], 0.0);
}

TEST(CalibrateIntrinsics, TooFewViewsAndBadInput) {
  const PinholeCamera truth = DefaultGalvoScannerModel().camera.camera;
  const PatternSpec spec = TestPattern();
  std::vector<PatternObservation> views = MakeViews(truth, spec, 4, 0.2, 24);
  // One view with only 3 corners: unusable, leaving 3 of 4.
  views[1].corner_ids.resize(3);
  views[1].corners_px.resize(3);
  try {
    CalibrateIntrinsics(spec, views, truth.width_px, truth.height_px);
    ADD_FAILURE() << "3 usable views accepted with min_views 4";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("3 of 4 views usable, need 4"), std::string::npos)
        << e.what();
  }
  IntrinsicsOptions three;
  three.min_views = 3;
  const IntrinsicsResult r =
      CalibrateIntrinsics(spec, views, truth.width_px, truth.height_px, three);
  EXPECT_TRUE(r.views[1].rejected);
  EXPECT_TRUE(std::isnan(r.views[1].rms_px));

  std::vector<PatternObservation> with_nan = views;
  with_nan[2].corners_px[0].x() = std::nan("");
  EXPECT_THROW(CalibrateIntrinsics(spec, with_nan, truth.width_px, truth.height_px, three), Error);
  EXPECT_THROW(CalibrateIntrinsics(spec, views, 0, truth.height_px, three), Error);
  IntrinsicsOptions bad;
  bad.min_views = 2;
  EXPECT_THROW(CalibrateIntrinsics(spec, views, truth.width_px, truth.height_px, bad), Error);
  bad = IntrinsicsOptions{};
  bad.reject_view_rms_px = 0.0;
  EXPECT_THROW(CalibrateIntrinsics(spec, views, truth.width_px, truth.height_px, bad), Error);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
