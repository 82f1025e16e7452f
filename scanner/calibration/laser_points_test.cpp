#include "scanner/calibration/laser_points.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The stripe of each step seen on each plane: the laser's rays in water hitting the plane,
// projected through the camera viewport.
struct Stripes {
  std::vector<std::vector<StripeObservation>> per_plane;
  std::vector<std::vector<Eigen::Vector3d>> true_points;  // per plane, in peak order
};

Stripes Observe(const GalvoScannerModel& scanner, const std::vector<Plane>& planes) {
  Stripes stripes;
  for (const Plane& plane : planes) {
    stripes.per_plane.emplace_back();
    stripes.true_points.emplace_back();
    for (int step : {-60, 0, 60}) {
      StripeObservation stripe{"step" + std::to_string(step), step, {}};
      const LaserFan fan = scanner.laser.FanAtStep(step);
      for (int k = 0; k <= 20; ++k) {
        const RayTrace ray = fan.RayInWater(0.3 * (-1.0 + 0.1 * k));
        const RayHit hit = IntersectRayPlane(ray.ray, plane);
        if (!ray.ok() || !hit.ok()) continue;
        const std::optional<Eigen::Vector2d> px = scanner.camera.ProjectPointInWater(hit.point);
        if (!px || !scanner.camera.camera.InImage(*px)) continue;
        stripe.peaks_px.push_back(*px);
        stripes.true_points.back().push_back(hit.point);
      }
      stripes.per_plane.back().push_back(stripe);
    }
  }
  return stripes;
}

TEST(LaserPointsTest, LiftsEveryPeakOntoItsPlane) {
  const GalvoScannerModel scanner = DefaultGalvoScannerModel();
  const Eigen::Vector3d n1 =
      Eigen::AngleAxisd(12.0 * kDeg, Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitZ();
  const std::vector<Plane> planes = {Plane{Eigen::Vector3d::UnitZ(), 0.7},
                                     Plane{n1, n1.dot(Eigen::Vector3d(0.1, 0.0, 1.1))}};
  const Stripes stripes = Observe(scanner, planes);
  const std::vector<LaserCalibrationPoint> points =
      LaserCalibrationPoints(scanner.camera, planes, stripes.per_plane);
  const size_t expected = stripes.true_points[0].size() + stripes.true_points[1].size();
  ASSERT_GT(expected, 60u);
  ASSERT_EQ(points.size(), expected);
  size_t k = 0;
  for (int i = 0; i < 2; ++i) {
    for (const Eigen::Vector3d& truth : stripes.true_points[static_cast<size_t>(i)]) {
      EXPECT_EQ(points[k].plane, i);
      EXPECT_LT((points[k].p_C - truth).norm(), 1e-9);
      EXPECT_NEAR(planes[static_cast<size_t>(i)].normal.dot(points[k].p_C),
                  planes[static_cast<size_t>(i)].offset_m, 1e-12);
      ++k;
    }
  }
  EXPECT_EQ(points.front().mirror_step, -60);
  EXPECT_EQ(points.back().mirror_step, 60);
}

TEST(LaserPointsTest, SkipsPeaksWhoseRayMissesThePlane) {
  const GalvoScannerModel scanner = DefaultGalvoScannerModel();
  StripeObservation stripe{"", 5, {Eigen::Vector2d(900.0, 500.0), Eigen::Vector2d(1100.0, 300.0)}};
  // A plane behind the camera, and the plane x = 0, which both rays leave behind them: each
  // starts on the viewport on its own side of it and heads further out.
  const std::vector<Plane> planes = {Plane{Eigen::Vector3d::UnitZ(), -1.0},
                                     Plane{Eigen::Vector3d::UnitX(), 0.0}};
  const std::vector<LaserCalibrationPoint> points =
      LaserCalibrationPoints(scanner.camera, planes, {{stripe}, {stripe}});
  EXPECT_TRUE(points.empty());
}

TEST(LaserPointsTest, RejectsMismatchedOrNonFiniteInput) {
  const GalvoScannerModel scanner = DefaultGalvoScannerModel();
  const std::vector<Plane> planes = {Plane{Eigen::Vector3d::UnitZ(), 1.0}};
  EXPECT_THROW(LaserCalibrationPoints(scanner.camera, planes, {}), Error);
  StripeObservation bad{"img.png", 0, {Eigen::Vector2d(std::nan(""), 1.0)}};
  EXPECT_THROW(LaserCalibrationPoints(scanner.camera, planes, {{bad}}), Error);
  EXPECT_THROW(
      LaserCalibrationPoints(scanner.camera, {Plane{Eigen::Vector3d(0.0, 0.0, 2.0), 1.0}}, {{}}),
      Error);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
