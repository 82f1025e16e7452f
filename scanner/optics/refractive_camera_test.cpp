#include "scanner/optics/refractive_camera.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <optional>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Pixels every 16 px over the whole image, with the last pixel centres and the image borders
// (-0.5 and size - 0.5) on both axes.
std::vector<Eigen::Vector2d> WholeImageGrid(const PinholeCamera& c) {
  std::vector<double> us, vs;
  for (int u = 0; u < c.width_px; u += 16) us.push_back(u);
  for (int v = 0; v < c.height_px; v += 16) vs.push_back(v);
  us.insert(us.end(), {-0.5, c.width_px - 1.0, c.width_px - 0.5});
  vs.insert(vs.end(), {-0.5, c.height_px - 1.0, c.height_px - 0.5});
  std::vector<Eigen::Vector2d> grid;
  for (double v : vs) {
    for (double u : us) grid.emplace_back(u, v);
  }
  return grid;
}

// pixel -> PixelToRayInWater -> point 0.2, 1 and 5 m along the water ray (from the outer face)
// -> ProjectPointInWater -> pixel. Returns the largest pixel error.
double MaxRoundTripErrorPx(const RefractiveCamera& camera) {
  double max_error_px = 0.0;
  for (const Eigen::Vector2d& uv : WholeImageGrid(camera.camera)) {
    const RayTrace in_water = camera.PixelToRayInWater(uv);
    EXPECT_TRUE(in_water.ok()) << "pixel " << uv.transpose() << ": " << ToString(in_water.status);
    if (!in_water.ok()) continue;
    for (double range_m : {0.2, 1.0, 5.0}) {
      const std::optional<Eigen::Vector2d> back =
          camera.ProjectPointInWater(in_water.ray.At(range_m));
      EXPECT_TRUE(back.has_value()) << "pixel " << uv.transpose() << " range " << range_m;
      if (!back) continue;
      const double error_px = (*back - uv).norm();
      max_error_px = std::max(max_error_px, error_px);
      EXPECT_LT(error_px, 1e-6) << "pixel " << uv.transpose() << " range " << range_m << " m";
    }
  }
  return max_error_px;
}

// Measured: max round-trip error 9.3e-13 px over the whole image (default scanner camera).
TEST(RefractiveCameraTest, RoundTripOverWholeImageDefaultCamera) {
  const RefractiveCamera camera = DefaultGalvoScannerModel().camera;
  ASSERT_NO_THROW(camera.Check());
  const double max_error_px = MaxRoundTripErrorPx(camera);
  std::cout << "[ measured ] default camera: max pixel round-trip error " << max_error_px
            << " px\n";
}

// Measured: max round-trip error 1.4e-12 px over the whole image (viewport tilted 20 deg).
TEST(RefractiveCameraTest, RoundTripOverWholeImageViewportTilted20Deg) {
  RefractiveCamera camera = DefaultGalvoScannerModel().camera;
  camera.viewport.normal =
      Eigen::AngleAxisd(20.0 * kDeg, Eigen::Vector3d(0.6, 0.8, 0.0)) * Eigen::Vector3d::UnitZ();
  ASSERT_NO_THROW(camera.Check());
  const double max_error_px = MaxRoundTripErrorPx(camera);
  std::cout << "[ measured ] viewport tilted 20 deg: max pixel round-trip error " << max_error_px
            << " px\n";
}

TEST(RefractiveCameraTest, PointsNotInFrontOfTheViewportDoNotProject) {
  const RefractiveCamera camera = DefaultGalvoScannerModel().camera;
  EXPECT_FALSE(camera.ProjectPointInWater({0.1, 0.0, 0.02}).has_value());   // in the housing
  EXPECT_FALSE(camera.ProjectPointInWater({0.1, 0.0, 0.035}).has_value());  // in the glass
  EXPECT_FALSE(camera.ProjectPointInWater({0.1, 0.0, -1.0}).has_value());   // behind
}

TEST(RefractiveCameraTest, CheckRequiresTheCameraCentreInsideTheHousing) {
  RefractiveCamera camera = DefaultGalvoScannerModel().camera;
  camera.viewport.distance_m = -0.01;
  EXPECT_THROW(camera.Check(), Error);
}

}  // namespace
}  // namespace uwscan::scanner
