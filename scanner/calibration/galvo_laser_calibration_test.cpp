#include "scanner/calibration/galvo_laser_calibration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/random_draws.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The default scanner's laser in air: its viewport still shifts the rays, without bending them.
GalvoLaser TrueLaserInAir() {
  GalvoLaser laser = DefaultGalvoScannerModel().laser;
  laser.viewport.n_water = 1.0;
  return laser;
}

GalvoLaser UnderWater(GalvoLaser laser) {
  laser.viewport.n_water = DefaultGalvoScannerModel().laser.viewport.n_water;
  return laser;
}

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

// Stripes of 8 mirror steps over the range on every board, `per_stripe` rays spread over
// `fan_fraction` of the aperture, each point moved by isotropic Gaussian noise.
std::vector<LaserCalibrationPoint> Points(const GalvoLaser& laser, double noise_m, unsigned seed,
                                          double fan_fraction = 1.0, int per_stripe = 50) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const std::vector<Plane> planes = ProjectionPlanes();
  std::vector<LaserCalibrationPoint> points;
  for (size_t i = 0; i < planes.size(); ++i) {
    for (int step : {-100, -70, -40, -10, 20, 50, 80, 100}) {
      const LaserFan fan = laser.FanAtStep(step);
      for (int k = 0; k < per_stripe; ++k) {
        const double s = fan_fraction * laser.MaxFanTan() * (-1.0 + 2.0 * k / (per_stripe - 1));
        const RayTrace ray = fan.RayInWater(s);
        const RayHit hit = IntersectRayPlane(ray.ray, planes[i]);
        if (!ray.ok() || !hit.ok()) continue;
        const Eigen::Vector3d p = hit.point + noise_m * DrawVector3(noise, rng);
        points.push_back(
            LaserCalibrationPoint{static_cast<int>(i), step, Eigen::Vector2d::Zero(), p});
      }
    }
  }
  return points;
}

// Largest distance, metres, of points of `a`'s fans (every 20th step, 11 rays over the
// aperture, 0.5 to 1.5 m beyond the viewport) from `b`'s fans. Independent of the gauges.
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

Eigen::Vector3d RandomUnit(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return DrawVector3(n, rng).normalized();
}

// Every pose turned by `angle_rad` about a random axis and moved by `position_m` in a random
// direction; rho_s off by 2 %, delta by `position_m`. With only_estimated the turns and moves
// avoid what the refinement holds (turn of {L} about z_L, emitter within its plane, mirror turn
// about y_M, mirror move along y_M), so that the truth stays reachable from the start.
GalvoLaser Perturbed(GalvoLaser laser, double position_m, double angle_rad, unsigned seed,
                     bool only_estimated = false) {
  std::mt19937 rng(seed);
  for (int which = 0; which < 2; ++which) {
    Eigen::Isometry3d& T = which == 0 ? laser.T_C_L : laser.T_C_M;
    Eigen::Vector3d axis = RandomUnit(rng);
    if (only_estimated) axis[which == 0 ? 2 : 1] = 0.0;  // in the frame's own axes
    T.linear() = T.linear() * Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
    Eigen::Vector3d move = RandomUnit(rng);
    if (only_estimated && which == 0) move = T.linear().col(2);
    if (only_estimated && which == 1) move -= move.dot(T.linear().col(1)) * T.linear().col(1);
    T.translation() += position_m * move.normalized();
  }
  laser.mirror_step_rad *= 1.02;
  laser.rotation_distance_m += position_m;
  return laser;
}

// `truth` moved along its gauges to match `estimate`: the mirror turned about its axis to the
// estimate's zero angle with the laser turned twice as far about the axis line (no change of
// the fans when delta = 0, ~1e-7 of the turn otherwise), {L} turned about z_L so that x_L lines
// up, the mirror origin slid along the axis to the estimate's.
GalvoLaser GaugeAligned(GalvoLaser truth, const GalvoLaser& estimate) {
  const Eigen::Vector3d axis = truth.T_C_M.linear().col(1), t_M = truth.T_C_M.translation();
  const Eigen::Vector3d m_truth = truth.T_C_M.linear().col(2),
                        m_est = estimate.T_C_M.linear().col(2);
  const double beta = std::atan2(axis.dot(m_truth.cross(m_est)), m_truth.dot(m_est));
  const Eigen::Matrix3d turn_mirror = Eigen::AngleAxisd(beta, axis).toRotationMatrix();
  const Eigen::Matrix3d turn_laser = Eigen::AngleAxisd(2.0 * beta, axis).toRotationMatrix();
  truth.T_C_M.linear() = turn_mirror * truth.T_C_M.linear();
  truth.T_C_L.linear() = turn_laser * truth.T_C_L.linear();
  truth.T_C_L.translation() = t_M + turn_laser * (truth.T_C_L.translation() - t_M);

  const Eigen::Matrix3d R = truth.T_C_L.linear();
  const Eigen::Vector3d x_est = estimate.T_C_L.linear().col(0);
  const double turn = std::atan2(x_est.dot(R.col(1)), x_est.dot(R.col(0)));
  truth.T_C_L.linear() = R * Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  truth.T_C_M.translation() +=
      (estimate.T_C_M.translation() - truth.T_C_M.translation()).dot(axis) * axis;
  return truth;
}

// The estimate's error in the coordinates its std devs are given in.
struct Errors {
  Eigen::Vector3d laser_rotation_rad, laser_position_m;
  Eigen::Vector3d mirror_rotation_rad, mirror_position_m;
  double mirror_step_rad, rotation_distance_m;
};
Errors ErrorsOf(const GalvoLaser& estimate, const GalvoLaser& truth) {
  const GalvoLaser t = GaugeAligned(truth, estimate);
  const auto log = [](const Eigen::Matrix3d& R) {
    const Eigen::AngleAxisd aa(R);
    return Eigen::Vector3d(aa.angle() * aa.axis());
  };
  const Eigen::Matrix3d R_L = estimate.T_C_L.linear(), R_M = estimate.T_C_M.linear();
  return Errors{log(R_L.transpose() * t.T_C_L.linear()),
                R_L.transpose() * (estimate.T_C_L.translation() - t.T_C_L.translation()),
                log(R_M.transpose() * t.T_C_M.linear()),
                R_M.transpose() * (estimate.T_C_M.translation() - t.T_C_M.translation()),
                estimate.mirror_step_rad - t.mirror_step_rad,
                estimate.rotation_distance_m - t.rotation_distance_m};
}

void Print(const char* what, const GalvoLaserCalibrationResult& r, const Errors& e) {
  const GalvoLaserStdDevs& s = r.std_devs;
  std::cout << what << ": rms " << r.residual_rms_m << " m, max " << r.residual_max_m
            << " m, iterations " << r.iterations << ", converged " << r.converged << "\n"
            << "  error (sd): laser rotation [" << e.laser_rotation_rad.transpose() << "] ("
            << s.laser_rotation_rad.transpose() << ") rad\n"
            << "              laser position [" << e.laser_position_m.transpose() << "] ("
            << s.laser_position_m.transpose() << ") m\n"
            << "              mirror rotation x,(zero angle),z ["
            << e.mirror_rotation_rad.transpose() << "] (" << s.mirror_axis_rad.transpose()
            << ") rad\n"
            << "              mirror position [" << e.mirror_position_m.transpose() << "] ("
            << s.mirror_position_m.transpose() << ") m\n"
            << "              mirror step " << e.mirror_step_rad << " (" << s.mirror_step_rad
            << ") rad, rotation distance " << e.rotation_distance_m << " (" << s.rotation_distance_m
            << ") m\n";
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

TEST(GalvoLaserCalibrationTest, DistanceToFanIsTheOffsetAlongTheSurfaceNormal) {
  const GalvoLaser laser = TrueLaserInAir();
  const LaserFan fan = laser.FanAtStep(37);
  const RayTrace a = fan.RayInWater(0.2), b = fan.RayInWater(0.2 + 1e-6);
  ASSERT_TRUE(a.ok() && b.ok());
  const Eigen::Vector3d on_fan = a.ray.At(0.9);
  const Eigen::Vector3d normal = a.ray.direction.cross(b.ray.At(0.9) - on_fan).normalized();
  EXPECT_LT(*DistanceToFan(laser, 37, on_fan), 1e-13);
  EXPECT_NEAR(*DistanceToFan(laser, 37, on_fan + 2e-3 * normal), 2e-3, 1e-8);
}

// Without delta and without a viewport the simplified model is the exact model.
TEST(GalvoLaserCalibrationTest, SimplifiedModelIsExactForPlanarFans) {
  GalvoLaser truth = TrueLaserInAir();
  truth.rotation_distance_m = 0.0;
  truth.viewport.thickness_m = 0.0;
  const GalvoLaser simplified = SimplifiedGalvoLaser(Points(truth, 0.0, 1), truth);
  EXPECT_LT(MaxFanGap(truth, simplified), 1e-9);
  EXPECT_NEAR(simplified.mirror_step_rad, truth.mirror_step_rad, 1e-12);
  // The emitter from the fan's edge rays, as in the seed.
  EXPECT_LT((simplified.T_C_L.translation() - truth.T_C_L.translation()).norm(), 1e-9);
}

// (a) Exact points: the simplified model is close (it ignores delta = 2 mm and the viewport's
// bending), the refinement recovers every parameter to rounding.
TEST(GalvoLaserCalibrationTest, RecoversEveryParameterFromExactPoints) {
  const GalvoLaser truth = TrueLaserInAir();
  const std::vector<LaserCalibrationPoint> points = Points(truth, 0.0, 1);
  const auto start = std::chrono::steady_clock::now();
  const GalvoLaserCalibrationResult result = CalibrateGalvoLaser(points, truth);
  const double seconds = Seconds(start);
  const Errors e = ErrorsOf(result.laser, truth);
  Print("exact", result, e);
  const Errors simplified = ErrorsOf(result.simplified, truth);
  std::cout << "  simplified: fan gap " << MaxFanGap(truth, result.simplified) << " m, rho_s error "
            << simplified.mirror_step_rad << " rad, axis error "
            << simplified.mirror_rotation_rad.transpose() << " rad; refined fan gap "
            << MaxFanGap(truth, result.laser) << " m (in water "
            << MaxFanGap(UnderWater(truth), UnderWater(result.laser)) << " m); " << points.size()
            << " points, " << seconds << " s\n";

  EXPECT_LT(MaxFanGap(truth, result.simplified), 5e-3);
  EXPECT_LT(std::abs(simplified.mirror_step_rad), 1e-4 * truth.mirror_step_rad);
  EXPECT_LT(simplified.mirror_rotation_rad.norm(), 1e-3);

  EXPECT_TRUE(result.emitter_from_edge_rays);
  EXPECT_TRUE(result.converged);
  EXPECT_LT(result.residual_rms_m, 1e-12);
  EXPECT_LT(MaxFanGap(truth, result.laser), 1e-11);
  EXPECT_LT(MaxFanGap(UnderWater(truth), UnderWater(result.laser)), 1e-10);
  EXPECT_LT(e.laser_rotation_rad.norm(), 1e-9);
  EXPECT_LT(e.laser_position_m.norm(), 1e-9);  // in the plane: from the edge rays
  EXPECT_LT(e.mirror_rotation_rad.norm(), 1e-9);
  EXPECT_LT(e.mirror_position_m.norm(), 1e-9);
  EXPECT_LT(std::abs(e.mirror_step_rad), 1e-9 * truth.mirror_step_rad);
  EXPECT_LT(std::abs(e.rotation_distance_m), 1e-9);
}

// Stripes cut short (60 % of the fan): the seed's edge-ray emitter is unavailable, the emitter
// stays where the CAD puts it in the laser plane, and the rest absorbs its error: the in-air
// fans stay within micrometres (the in-water ones do not; see the header).
TEST(GalvoLaserCalibrationTest, HoldsTheCadEmitterWhenStripesAreCut) {
  const GalvoLaser truth = TrueLaserInAir();
  GalvoLaser cad = truth;
  const Eigen::Vector3d emitter_error(0.003, -0.002, 0.002);
  cad.T_C_L.translation() += emitter_error;
  const GalvoLaserCalibrationResult result = CalibrateGalvoLaser(Points(truth, 0.0, 1, 0.6), cad);
  const Errors e = ErrorsOf(result.laser, truth);
  const double in_water = MaxFanGap(UnderWater(truth), UnderWater(result.laser));
  std::cout << "cut stripes, CAD emitter 3 mm off in the plane: rms " << result.residual_rms_m
            << " m, fan gap " << MaxFanGap(truth, result.laser) << " m in air, " << in_water
            << " m in water; emitter error " << e.laser_position_m.transpose() << " m\n";
  EXPECT_FALSE(result.emitter_from_edge_rays);
  EXPECT_NEAR(e.laser_position_m.x(), -0.003, 1e-5);  // held (x_L = -x_C, y_L = y_C)
  EXPECT_NEAR(e.laser_position_m.y(), -0.002, 1e-5);
  EXPECT_TRUE(result.converged);
  EXPECT_LT(result.residual_rms_m, 2e-6);
  EXPECT_LT(MaxFanGap(truth, result.laser), 1e-5);
}

// (b) 0.1 mm of noise: every estimated parameter within 4 standard deviations.
TEST(GalvoLaserCalibrationTest, NoisyPointsLandWithinTheirStandardDeviations) {
  const GalvoLaser truth = TrueLaserInAir();
  const double noise_m = 1e-4;
  const GalvoLaserCalibrationResult result = CalibrateGalvoLaser(Points(truth, noise_m, 2), truth);
  const Errors e = ErrorsOf(result.laser, truth);
  const GalvoLaserStdDevs& s = result.std_devs;
  Print("0.1 mm noise", result, e);
  std::cout << "  fan gap " << MaxFanGap(truth, result.laser) << " m in air, "
            << MaxFanGap(UnderWater(truth), UnderWater(result.laser)) << " m in water\n";
  EXPECT_TRUE(result.converged);
  EXPECT_NEAR(result.residual_rms_m, noise_m, 0.1 * noise_m);  // one of three axes: normal
  constexpr double k = 4.0;
  for (int i = 0; i < 2; ++i)
    EXPECT_LT(std::abs(e.laser_rotation_rad[i]), k * s.laser_rotation_rad[i]);
  EXPECT_LT(std::abs(e.laser_position_m[2]), k * s.laser_position_m[2]);
  // The emitter within its plane, from the stripes' ends, is far better than the viewport's
  // bending could tell (8-18 mm, see the header).
  EXPECT_LT(e.laser_position_m.head<2>().norm(), 1e-3);
  EXPECT_LT(std::abs(e.mirror_rotation_rad[0]), k * s.mirror_axis_rad[0]);
  EXPECT_LT(std::abs(e.mirror_rotation_rad[2]), k * s.mirror_axis_rad[1]);
  EXPECT_LT(std::abs(e.mirror_position_m[0]), k * s.mirror_position_m[0]);
  EXPECT_LT(std::abs(e.mirror_position_m[2]), k * s.mirror_position_m[1]);
  EXPECT_LT(std::abs(e.mirror_step_rad), k * s.mirror_step_rad);
  EXPECT_LT(std::abs(e.rotation_distance_m), k * s.rotation_distance_m);
  // What is held reports 0.
  EXPECT_EQ(s.laser_rotation_rad[2], 0.0);
  EXPECT_EQ(s.laser_position_m[0], 0.0);
  // The light surfaces are what the points pin down: far better than any single parameter.
  EXPECT_LT(MaxFanGap(truth, result.laser), 0.5 * noise_m);
}

// (c) Started 5 mm / 2 degrees from the truth (every estimated pose component, rho_s 2 %,
// delta 5 mm), the refinement ends where it ends when started from the truth.
TEST(GalvoLaserCalibrationTest, RefinementConvergesFromAPoorStart) {
  const GalvoLaser truth = TrueLaserInAir();
  for (double noise_m : {0.0, 1e-4}) {
    const std::vector<LaserCalibrationPoint> points = Points(truth, noise_m, 3);
    const GalvoLaserCalibrationResult from_truth = RefineGalvoLaser(points, truth);
    for (unsigned seed : {11u, 12u, 13u}) {
      const auto start = std::chrono::steady_clock::now();
      const GalvoLaser poor = Perturbed(truth, 0.005, 2.0 * kDeg, seed, true);
      const GalvoLaserCalibrationResult from_poor = RefineGalvoLaser(points, poor);
      const double seconds = Seconds(start);
      const Errors e = ErrorsOf(from_poor.laser, from_truth.laser);
      const double gap = MaxFanGap(from_truth.laser, from_poor.laser);
      std::cout << "noise " << noise_m << " seed " << seed << ": start fan gap "
                << MaxFanGap(truth, poor) << " m, " << from_poor.iterations
                << " iterations (from the truth " << from_truth.iterations << "), " << seconds
                << " s; answers differ by rotations " << e.laser_rotation_rad.norm() << ", "
                << e.mirror_rotation_rad.norm() << " rad, positions " << e.laser_position_m.norm()
                << ", " << e.mirror_position_m.norm() << " m, rho_s " << e.mirror_step_rad
                << ", delta " << e.rotation_distance_m << "; fans by " << gap << " m\n";
      EXPECT_TRUE(from_poor.converged);
      if (noise_m == 0.0) {
        EXPECT_LT(e.laser_rotation_rad.norm(), 1e-12);
        EXPECT_LT(e.mirror_rotation_rad.norm(), 1e-12);
        EXPECT_LT(e.laser_position_m.norm(), 1e-12);
        EXPECT_LT(e.mirror_position_m.norm(), 1e-12);
        EXPECT_LT(std::abs(e.mirror_step_rad), 1e-9 * truth.mirror_step_rad);
        EXPECT_LT(std::abs(e.rotation_distance_m), 1e-12);
        EXPECT_LT(gap, 1e-13);
      } else {
        // The held components are held on lines and slices through each run's own start, which
        // the noise moves the answer along: they part by ~noise x 2 degrees (20 um along the
        // laser plane's normal here; 58 um with another noise draw), in directions that hardly
        // move the fans.
        const GalvoLaserStdDevs& sd = from_truth.std_devs;
        EXPECT_LT(gap, 1e-7);
        EXPECT_LT(std::abs(e.mirror_step_rad), 0.01 * sd.mirror_step_rad);
        EXPECT_LT(std::abs(e.rotation_distance_m), 0.01 * sd.rotation_distance_m);
        EXPECT_LT(e.mirror_position_m.norm(), 0.01 * sd.mirror_position_m.norm());
        EXPECT_LT(e.laser_position_m.norm(), 0.1 * sd.laser_position_m.norm());
      }
    }
  }
}

// (c) The whole calibration from a CAD 5 mm / 2 degrees off in everything (held components
// too): the same light surfaces as from the exact CAD. Of what is held, the emitter comes from
// the data (edge rays) and the rest are gauges but the mirror's zero angle, whose 2 degrees
// delta turns into ~10 nm.
TEST(GalvoLaserCalibrationTest, CalibrationConvergesFromAPoorCad) {
  const GalvoLaser truth = TrueLaserInAir();
  for (double noise_m : {0.0, 1e-4}) {
    const std::vector<LaserCalibrationPoint> points = Points(truth, noise_m, 4);
    const GalvoLaserCalibrationResult from_truth = CalibrateGalvoLaser(points, truth);
    for (unsigned seed : {31u}) {
      const auto start = std::chrono::steady_clock::now();
      const GalvoLaserCalibrationResult from_poor =
          CalibrateGalvoLaser(points, Perturbed(truth, 0.005, 2.0 * kDeg, seed));
      const double seconds = Seconds(start);
      const double gap = MaxFanGap(from_truth.laser, from_poor.laser);
      std::cout << "noise " << noise_m << " CAD seed " << seed << ": " << from_poor.iterations
                << " iterations (from the truth " << from_truth.iterations << "), " << seconds
                << " s; fans differ by " << gap << " m in air, "
                << MaxFanGap(UnderWater(from_truth.laser), UnderWater(from_poor.laser))
                << " m in water; rho_s by "
                << from_poor.laser.mirror_step_rad - from_truth.laser.mirror_step_rad
                << ", delta by "
                << from_poor.laser.rotation_distance_m - from_truth.laser.rotation_distance_m
                << " (sd " << from_truth.std_devs.rotation_distance_m << ")\n";
      EXPECT_TRUE(from_poor.converged);
      EXPECT_TRUE(from_poor.emitter_from_edge_rays);
      EXPECT_LT(gap, 1e-7);
      EXPECT_NEAR(from_poor.laser.mirror_step_rad, from_truth.laser.mirror_step_rad, 1e-10);
    }
  }
}

TEST(GalvoLaserCalibrationTest, RejectsDataThatCannotDetermineTheModel) {
  const GalvoLaser truth = TrueLaserInAir();
  std::vector<LaserCalibrationPoint> one_board;
  for (const LaserCalibrationPoint& p : Points(truth, 0.0, 1)) {
    if (p.plane == 2) one_board.push_back(p);
  }
  EXPECT_THROW(SimplifiedGalvoLaser(one_board, truth), Error);  // each step's points collinear
  std::vector<LaserCalibrationPoint> two_steps;
  for (const LaserCalibrationPoint& p : Points(truth, 0.0, 1)) {
    if (p.mirror_step == -100 || p.mirror_step == 100) two_steps.push_back(p);
  }
  EXPECT_THROW(SimplifiedGalvoLaser(two_steps, truth), Error);
  EXPECT_THROW(RefineGalvoLaser(std::vector<LaserCalibrationPoint>(5, one_board[0]), truth), Error);
  std::vector<LaserCalibrationPoint> outside = Points(truth, 0.0, 1);
  outside[0].mirror_step = truth.step_max + 1;
  EXPECT_THROW(CalibrateGalvoLaser(outside, truth), Error);
  GalvoLaserCalibrationOptions options;
  options.max_iterations = 0;
  EXPECT_THROW(options.Check(), Error);
}

TEST(GalvoLaserCalibrationTest, FixedRotationDistanceStaysPut) {
  const GalvoLaser truth = TrueLaserInAir();
  GalvoLaserCalibrationOptions options;
  options.refine_rotation_distance = false;
  const GalvoLaserCalibrationResult result =
      RefineGalvoLaser(Points(truth, 0.0, 1), truth, options);
  EXPECT_EQ(result.laser.rotation_distance_m, truth.rotation_distance_m);
  EXPECT_EQ(result.std_devs.rotation_distance_m, 0.0);
  EXPECT_LT(result.residual_rms_m, 1e-12);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
