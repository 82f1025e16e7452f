#include "scanner/calibration/laser_viewport_calibration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>
#include <vector>

#include "scanner/calibration/galvo_laser_calibration.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/random_draws.hpp"
#include "scanner/triangulation/light_plane.hpp"
#include "scanner/triangulation/ray_ray_triangulator.hpp"

namespace uwscan::scanner::calibration {
namespace {

// The thickness is held by default (weakly observable); these tests also recover it.
LaserViewportCalibrationOptions RefineAll() {
  LaserViewportCalibrationOptions options;
  options.refine_thickness = true;
  return options;
}

constexpr double kDeg = std::numbers::pi / 180.0;

// Six boards from 0.5 to 1.3 m, each tilted by up to 20 degrees.
std::vector<Plane> ProjectionPlanes() {
  const double table[6][3] = {{0.5, 10, -15},  {0.65, -12, 8}, {0.8, 5, 20},
                              {0.95, -8, -10}, {1.1, 15, 5},   {1.3, -5, -20}};
  std::vector<Plane> planes;
  for (const auto& [distance, tilt_x_deg, tilt_y_deg] : table) {
    const Eigen::Vector3d normal = Eigen::AngleAxisd(tilt_x_deg * kDeg, Eigen::Vector3d::UnitX()) *
                                   Eigen::AngleAxisd(tilt_y_deg * kDeg, Eigen::Vector3d::UnitY()) *
                                   Eigen::Vector3d::UnitZ();
    planes.push_back(Plane{normal, normal.dot(Eigen::Vector3d(0.1, 0.0, distance))});
  }
  return planes;
}

// What the camera sees of 8 mirror steps' stripes on every board (~50 peaks per stripe), each
// point moved by isotropic Gaussian noise and its pixel re-projected, so that the calibration
// point stays on its pixel's camera ray (as LaserCalibrationPoints makes it).
std::vector<LaserCalibrationPoint> Points(const GalvoScannerModel& scanner, double noise_m,
                                          unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const std::vector<Plane> planes = ProjectionPlanes();
  std::vector<LaserCalibrationPoint> points;
  for (size_t i = 0; i < planes.size(); ++i) {
    for (int step : {-100, -70, -40, -10, 20, 50, 80, 100}) {
      const LaserFan fan = scanner.laser.FanAtStep(step);
      for (int k = 0; k <= 100; ++k) {
        const RayTrace ray = fan.RayInWater(scanner.laser.MaxFanTan() * (-1.0 + 0.02 * k));
        const RayHit hit = IntersectRayPlane(ray.ray, planes[i]);
        if (!ray.ok() || !hit.ok()) continue;
        const Eigen::Vector3d p = hit.point + noise_m * DrawVector3(noise, rng);
        const std::optional<Eigen::Vector2d> px = scanner.camera.ProjectPointInWater(p);
        if (!px || !scanner.camera.camera.InImage(*px)) continue;
        points.push_back(LaserCalibrationPoint{static_cast<int>(i), step, *px, p});
      }
    }
  }
  return points;
}

// The viewport moved by `position_m` (inner face along the normal, thickness) and its normal
// tilted by `angle_rad` about a random axis across it.
FlatViewport Perturbed(FlatViewport v, double position_m, double angle_rad, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector3d axis = DrawVector3(n, rng);
  axis = (axis - axis.dot(v.normal) * v.normal).normalized();
  v.normal = Eigen::AngleAxisd(angle_rad, axis) * v.normal;
  v.distance_m += position_m;
  v.thickness_m += position_m;
  return v;
}

GalvoScannerModel WithLaserViewport(GalvoScannerModel model, const FlatViewport& viewport) {
  model.laser.viewport = viewport;
  return model;
}

double Angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void Print(const char* what, const LaserViewportCalibrationResult& r, const FlatViewport& truth,
           double seconds) {
  std::cout << what << ": normal " << Angle(r.viewport.normal, truth.normal) << " (sd "
            << r.normal_std_rad << ") rad, distance " << r.viewport.distance_m - truth.distance_m
            << " (sd " << r.distance_std_m << ") m, thickness "
            << r.viewport.thickness_m - truth.thickness_m << " (sd " << r.thickness_std_m
            << ") m; rms " << r.residual_rms_m << " m, max " << r.residual_max_m << " m, "
            << r.points << " points, " << r.iterations << " iterations, converged " << r.converged
            << ", " << seconds << " s\n";
}

// (a) Exact points, started from a CAD 5 mm / 2 degrees off: the truth, to rounding.
TEST(LaserViewportCalibrationTest, RecoversTheViewportFromExactPoints) {
  const GalvoScannerModel truth = DefaultGalvoScannerModel();
  const std::vector<LaserCalibrationPoint> points = Points(truth, 0.0, 1);
  const FlatViewport cad = Perturbed(truth.laser.viewport, 0.005, 2.0 * kDeg, 1);
  const auto start = std::chrono::steady_clock::now();
  const LaserViewportCalibrationResult result =
      CalibrateLaserViewport(WithLaserViewport(truth, cad), points, RefineAll());
  Print("exact", result, truth.laser.viewport, Seconds(start));
  EXPECT_GT(points.size(), 1500u);
  EXPECT_TRUE(result.converged);
  EXPECT_LT(result.residual_rms_m, 1e-12);
  EXPECT_LT(Angle(result.viewport.normal, truth.laser.viewport.normal), 1e-10);
  EXPECT_NEAR(result.viewport.distance_m, truth.laser.viewport.distance_m, 1e-11);
  EXPECT_NEAR(result.viewport.thickness_m, truth.laser.viewport.thickness_m, 1e-11);

  // The seed's p+: the ray-ray triangulator with the refined viewport gives back the points.
  const RayRayTriangulator triangulator(WithLaserViewport(truth, result.viewport));
  double worst = 0.0;
  for (size_t k = 0; k < points.size(); k += 7) {
    const RayTrace camera = truth.camera.PixelToRayInWater(points[k].px);
    const TriangulatedPoint p = triangulator.TriangulateRay(points[k].mirror_step, camera.ray);
    ASSERT_TRUE(p.ok());
    worst = std::max(worst, (p.p_C - points[k].p_C).norm());
  }
  EXPECT_LT(worst, 1e-9);
}

// (b) 0.1 mm of noise: within 4 standard deviations.
TEST(LaserViewportCalibrationTest, NoisyPointsLandWithinTheirStandardDeviations) {
  const GalvoScannerModel truth = DefaultGalvoScannerModel();
  const FlatViewport cad = Perturbed(truth.laser.viewport, 0.002, 1.0 * kDeg, 2);
  const auto start = std::chrono::steady_clock::now();
  const LaserViewportCalibrationResult result =
      CalibrateLaserViewport(WithLaserViewport(truth, cad), Points(truth, 1e-4, 2), RefineAll());
  Print("0.1 mm noise", result, truth.laser.viewport, Seconds(start));
  EXPECT_TRUE(result.converged);
  EXPECT_LT(Angle(result.viewport.normal, truth.laser.viewport.normal),
            4.0 * result.normal_std_rad);
  EXPECT_LT(std::abs(result.viewport.distance_m - truth.laser.viewport.distance_m),
            4.0 * result.distance_std_m);
  EXPECT_LT(std::abs(result.viewport.thickness_m - truth.laser.viewport.thickness_m),
            4.0 * result.thickness_std_m);
}

// (c) Started 5 mm / 2 degrees from the truth: the same answer as started from the truth.
TEST(LaserViewportCalibrationTest, ConvergesFromAPoorStart) {
  const GalvoScannerModel truth = DefaultGalvoScannerModel();
  for (double noise_m : {0.0, 1e-4}) {
    const std::vector<LaserCalibrationPoint> points = Points(truth, noise_m, 3);
    const LaserViewportCalibrationResult from_truth =
        CalibrateLaserViewport(truth, points, RefineAll());
    for (unsigned seed : {21u, 22u, 23u}) {
      const auto start = std::chrono::steady_clock::now();
      const LaserViewportCalibrationResult from_poor = CalibrateLaserViewport(
          WithLaserViewport(truth, Perturbed(truth.laser.viewport, 0.005, 2.0 * kDeg, seed)),
          points, RefineAll());
      const double seconds = Seconds(start);
      const double normal = Angle(from_poor.viewport.normal, from_truth.viewport.normal);
      const double distance = from_poor.viewport.distance_m - from_truth.viewport.distance_m;
      const double thickness = from_poor.viewport.thickness_m - from_truth.viewport.thickness_m;
      std::cout << "noise " << noise_m << " seed " << seed << ": " << from_poor.iterations
                << " iterations (from the truth " << from_truth.iterations << "), " << seconds
                << " s; answers differ by " << normal << " rad, " << distance << " m, " << thickness
                << " m\n";
      EXPECT_TRUE(from_poor.converged);
      // Both runs stop where the relative cost change falls below the solver's tolerance; with
      // noise the cost stays finite, so that point lies farther (still < 0.1 nm) from the minimum.
      const double tolerance_m = noise_m == 0.0 ? 1e-11 : 1e-10;
      EXPECT_LT(normal, 1e-10);
      EXPECT_LT(std::abs(distance), tolerance_m);
      EXPECT_LT(std::abs(thickness), tolerance_m);
    }
  }
}

TEST(LaserViewportCalibrationTest, HeldThicknessStaysPut) {
  const GalvoScannerModel truth = DefaultGalvoScannerModel();
  FlatViewport cad = Perturbed(truth.laser.viewport, 0.003, 1.0 * kDeg, 4);
  cad.thickness_m = truth.laser.viewport.thickness_m;
  LaserViewportCalibrationOptions options;
  options.refine_thickness = false;
  const LaserViewportCalibrationResult result =
      CalibrateLaserViewport(WithLaserViewport(truth, cad), Points(truth, 0.0, 4), options);
  EXPECT_EQ(result.viewport.thickness_m, truth.laser.viewport.thickness_m);
  EXPECT_EQ(result.thickness_std_m, 0.0);
  EXPECT_LT(Angle(result.viewport.normal, truth.laser.viewport.normal), 1e-10);
  EXPECT_NEAR(result.viewport.distance_m, truth.laser.viewport.distance_m, 1e-11);
}

TEST(LaserViewportCalibrationTest, RejectsBadInput) {
  const GalvoScannerModel truth = DefaultGalvoScannerModel();
  std::vector<LaserCalibrationPoint> points = Points(truth, 0.0, 5);
  LaserViewportCalibrationOptions options;
  options.max_iterations = 0;
  EXPECT_THROW(CalibrateLaserViewport(truth, points, options), Error);
  EXPECT_THROW(CalibrateLaserViewport(truth, {points.begin(), points.begin() + 3}), Error);
  points[0].mirror_step = truth.laser.step_min - 1;
  EXPECT_THROW(CalibrateLaserViewport(truth, points), Error);
}

// Largest distance, metres, of points of `a`'s fans (every 20th step, 11 rays over the
// aperture, 0.5 to 1.5 m beyond the viewport) from `b`'s fans.
double MaxFanGap(const GalvoLaser& a, const GalvoLaser& b) {
  double gap = 0.0;
  for (int step = a.step_min; step <= a.step_max; step += 20) {
    const LaserFan fan = a.FanAtStep(step);
    for (int k = 0; k <= 10; ++k) {
      const RayTrace ray = fan.RayInWater(a.MaxFanTan() * (-1.0 + 0.2 * k));
      if (!ray.ok()) continue;
      for (double range : {0.5, 1.0, 1.5}) {
        const std::optional<double> d = DistanceToFan(b, step, ray.ray.At(range));
        gap = std::max(gap, d ? *d : 1e9);
      }
    }
  }
  return gap;
}

// The whole laser chain: the in-air calibration on what the camera sees (stripes cut by the
// image, so the emitter stays at the CAD's, here 2 mm off in its plane), then the viewport
// under water, which absorbs part of what that emitter error does to the in-water fans.
TEST(LaserViewportCalibrationTest, AbsorbsPartOfTheInAirCalibrationsEmitterError) {
  const GalvoScannerModel truth = DefaultGalvoScannerModel();
  GalvoScannerModel in_air = truth;
  in_air.laser.viewport.n_water = in_air.camera.viewport.n_water = 1.0;
  GalvoLaser cad = truth.laser;
  cad.T_C_L.translation() += Eigen::Vector3d(0.002, 0.0, 0.0);  // along the central ray
  const GalvoLaserCalibrationResult in_air_result =
      CalibrateGalvoLaser(Points(in_air, 0.0, 6), cad);
  ASSERT_FALSE(in_air_result.emitter_from_edge_rays);
  GalvoScannerModel model = truth;
  model.laser = in_air_result.laser;
  const double gap_true_viewport = MaxFanGap(truth.laser, model.laser);
  model.laser.viewport = Perturbed(truth.laser.viewport, 0.005, 2.0 * kDeg, 6);  // the CAD
  const LaserViewportCalibrationResult result =
      CalibrateLaserViewport(model, Points(truth, 0.0, 7), RefineAll());
  model.laser.viewport = result.viewport;
  const double gap_calibrated = MaxFanGap(truth.laser, model.laser);
  GalvoLaser result_in_air = in_air_result.laser;
  result_in_air.viewport.n_water = 1.0;
  std::cout << "in air: fan gap " << MaxFanGap(in_air.laser, result_in_air)
            << " m; in water: " << gap_true_viewport << " m with the true viewport, "
            << gap_calibrated << " m with the calibrated one (rms " << result.residual_rms_m
            << " m, normal off by " << Angle(result.viewport.normal, truth.laser.viewport.normal)
            << " rad, distance " << result.viewport.distance_m - truth.laser.viewport.distance_m
            << " m, thickness " << result.viewport.thickness_m - truth.laser.viewport.thickness_m
            << " m)\n";
  EXPECT_TRUE(result.converged);
  EXPECT_LT(gap_calibrated, gap_true_viewport);
  EXPECT_LT(result.residual_rms_m, 3e-5);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
