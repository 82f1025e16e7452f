#include "scanner/lasers/mems_laser.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"
#include "scanner/optics/refraction.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

MemsLaser DefaultLaser() { return DefaultMemsScannerModel().laser; }

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

std::string CheckError(const MemsLaser& laser) {
  try {
    laser.Check();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "Check() passed";
  return "";
}

TEST(MemsLaser, DefaultGeometryMatchesTheSeedPrototype) {
  const MemsLaser laser = DefaultLaser();
  EXPECT_NO_THROW(laser.Check());
  // The zero-volt beam leaves the box square to its viewport (no refraction), toed in 25 deg.
  const RayTrace centre = laser.RayInWater(Eigen::Vector2d::Zero());
  ASSERT_TRUE(centre.ok());
  EXPECT_LT(AngleBetween(centre.ray.direction, laser.viewport.normal), 1e-12);
  EXPECT_NEAR(std::atan2(-centre.ray.direction.x(), centre.ray.direction.z()), 25.0 * kDeg, 1e-12);
  // ... and crosses the camera axis in the 1-1.5 m working range.
  const double t = -centre.ray.origin.x() / centre.ray.direction.x();
  EXPECT_GT(centre.ray.At(t).z(), 1.0);
  EXPECT_LT(centre.ray.At(t).z(), 1.5);

  // FoV in water about 35 x 35 degrees (seed): x sweeps across, y along the lines.
  const double v = laser.max_volts;
  auto angle = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const RayTrace ra = laser.RayInWater(a), rb = laser.RayInWater(b);
    EXPECT_TRUE(ra.ok() && rb.ok());
    return AngleBetween(ra.ray.direction, rb.ray.direction);
  };
  const double fov_x = angle({-v, 0.0}, {v, 0.0}), fov_y = angle({0.0, -v}, {0.0, v});
  std::cout << "[ measured ] MEMS FoV in water " << fov_x / kDeg << " x " << fov_y / kDeg
            << " deg\n";
  EXPECT_NEAR(fov_x, 35.0 * kDeg, 1.5 * kDeg);
  EXPECT_NEAR(fov_y, 35.0 * kDeg, 1.5 * kDeg);
  // Positive volts move the beam towards +x_C (across) and +y_C (down).
  const Eigen::Vector3d d0 = centre.ray.direction;
  EXPECT_GT(laser.RayInWater({1.0, 0.0}).ray.direction.x(), d0.x());
  EXPECT_GT(laser.RayInWater({0.0, 1.0}).ray.direction.y(), d0.y());
}

TEST(MemsLaser, StaticResponseIsOddSaturatingAndInvertible) {
  const MemsLaser laser = DefaultLaser();
  const double vmax = laser.max_volts;
  for (const double v : {0.0, 1e-9, 1e-3, 0.37, 2.5, 5.0, 9.99, vmax}) {
    const Eigen::Vector2d volts(v, -0.5 * v);
    const Eigen::Vector2d tilt = laser.TiltFromVolts(volts);
    EXPECT_EQ(laser.TiltFromVolts(-volts), -tilt);  // odd, exactly
    const std::optional<Eigen::Vector2d> back = laser.VoltsFromTilt(tilt);
    ASSERT_TRUE(back.has_value()) << v;
    EXPECT_NEAR(back->x(), volts.x(), 1e-13 * vmax) << v;
    EXPECT_NEAR(back->y(), volts.y(), 1e-13 * vmax) << v;
  }
  // Reaches max_tilt at max_volts; beyond the drive range there is no voltage.
  const Eigen::Vector2d at_max = laser.TiltFromVolts(Eigen::Vector2d::Constant(vmax));
  EXPECT_NEAR(at_max.x(), laser.max_tilt_rad.x(), 1e-15);
  EXPECT_NEAR(at_max.y(), laser.max_tilt_rad.y(), 1e-15);
  EXPECT_FALSE(laser.VoltsFromTilt(1.001 * laser.max_tilt_rad).has_value());
  EXPECT_FALSE(laser.VoltsFromTilt(Eigen::Vector2d(0.0, -1.001 * laser.max_tilt_rad.y())));

  // Linear for small voltages, with the slope falling to sech^2(s) at max_volts.
  const double s = laser.saturation.x();
  const double small_signal = laser.max_tilt_rad.x() * s / (vmax * std::tanh(s));
  EXPECT_NEAR(laser.TiltFromVolts({1e-6, 0.0}).x() / 1e-6, small_signal, 1e-9 * small_signal);
  const double h = 1e-5;
  const double slope_at_max =
      (laser.TiltFromVolts({vmax + h, 0.0}).x() - laser.TiltFromVolts({vmax - h, 0.0}).x()) /
      (2.0 * h);
  EXPECT_NEAR(slope_at_max / small_signal, 1.0 / std::pow(std::cosh(s), 2), 1e-8);
}

TEST(MemsLaser, MirrorFollowsTheGimbalAndTheReflectionLaw) {
  const MemsLaser laser = DefaultLaser();
  for (const Eigen::Vector2d& tilt :
       {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.05, -0.03), Eigen::Vector2d(-0.08, 0.07)}) {
    // Outer gimbal about x_M, inner about the carried y_M.
    const Eigen::Vector3d expected =
        laser.T_C_M.linear() *
        (Eigen::AngleAxisd(tilt.x(), Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(tilt.y(), Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitZ());
    const Eigen::Vector3d n = laser.MirrorNormal_C(tilt);
    EXPECT_LT((n - expected).norm(), 1e-15);
    const RayTrace reflected = laser.RayAfterMirror(tilt);
    ASSERT_TRUE(reflected.ok());
    // Starts on the mirror plane through the pivot; angle of incidence = angle of reflection.
    EXPECT_NEAR(n.dot(reflected.ray.origin - laser.T_C_M.translation()), 0.0, 1e-16);
    EXPECT_NEAR(AngleBetween(-laser.emitter_direction_C, n),
                AngleBetween(reflected.ray.direction, n), 1e-14);
  }
  // y_M is normal to the plane of incidence in the default box: turning the mirror about it
  // by delta turns the reflected beam by exactly 2 delta.
  const double delta = 0.03;
  const Eigen::Vector3d r0 = laser.RayAfterMirror({0.0, 0.0}).ray.direction;
  const Eigen::Vector3d r1 = laser.RayAfterMirror({0.0, delta}).ray.direction;
  EXPECT_NEAR(AngleBetween(r0, r1), 2.0 * delta, 1e-14);
}

TEST(MemsLaser, LensMultipliesTheAngleAndKeepsTheAzimuth) {
  const MemsLaser laser = DefaultLaser();
  const Eigen::Matrix3d R_Lens_C = laser.T_C_Lens.linear().transpose();
  for (const Eigen::Vector2d& tilt :
       {Eigen::Vector2d(0.02, 0.0), Eigen::Vector2d(0.0, -0.05), Eigen::Vector2d(0.07, 0.06),
        Eigen::Vector2d(1e-9, 0.0), Eigen::Vector2d(-3e-10, 2e-10)}) {
    const RayTrace before = laser.RayAfterMirror(tilt);
    const RayTrace after = laser.RayAfterLens(tilt);
    ASSERT_TRUE(before.ok() && after.ok());
    const Eigen::Vector3d a = R_Lens_C * before.ray.direction;
    const Eigen::Vector3d b = R_Lens_C * after.ray.direction;
    const double theta_in = std::atan2(a.head<2>().norm(), a.z());
    const double theta_out = std::atan2(b.head<2>().norm(), b.z());
    // Relative precision even a nanoradian off the axis: no cancellation near it.
    EXPECT_NEAR(theta_out, laser.lens_gain * theta_in, 1e-12 * theta_out) << tilt.transpose();
    EXPECT_NEAR(std::atan2(a.y(), a.x()), std::atan2(b.y(), b.x()), 1e-12) << tilt.transpose();
    // Leaves from the lens plane, where the incoming beam crosses it.
    const Eigen::Vector3d origin_Lens = laser.T_C_Lens.inverse() * after.ray.origin;
    EXPECT_NEAR(origin_Lens.z(), 0.0, 1e-15);
    const double t = (after.ray.origin - before.ray.origin).dot(before.ray.direction);
    EXPECT_LT((before.ray.At(t) - after.ray.origin).norm(), 1e-15);
  }
  // On the axis the lens leaves the beam alone.
  const RayTrace on_axis = laser.RayAfterLens(Eigen::Vector2d::Zero());
  EXPECT_LT(AngleBetween(on_axis.ray.direction, laser.T_C_Lens.linear().col(2)), 1e-15);

  // A lens bending the beam to 90 degrees or more: an expected miss, not an error.
  MemsLaser wide = laser;
  wide.lens_gain = 10.0;
  EXPECT_EQ(wide.RayAfterLens({0.08, 0.07}).status, HitStatus::kOutsideSurface);
}

TEST(MemsLaser, WaterRayIsTheLensRayThroughTheViewport) {
  const MemsLaser laser = DefaultLaser();
  const Eigen::Vector2d volts(3.3, -7.1);
  const RayTrace in_air = laser.RayAfterLens(laser.TiltFromVolts(volts));
  const RayTrace expected = TraceOut(laser.viewport, in_air.ray);
  const RayTrace in_water = laser.RayInWater(volts);
  ASSERT_TRUE(in_water.ok());
  EXPECT_EQ(in_water.ray.origin, expected.ray.origin);
  EXPECT_EQ(in_water.ray.direction, expected.ray.direction);
  // Snell: n_air sin(air) = n_water sin(water) about the viewport normal.
  const Eigen::Vector3d& n = laser.viewport.normal;
  EXPECT_NEAR(laser.viewport.n_air * in_air.ray.direction.cross(n).norm(),
              laser.viewport.n_water * in_water.ray.direction.cross(n).norm(), 1e-15);
}

TEST(MemsLaser, CheckNamesTheField) {
  MemsLaser laser = DefaultLaser();
  laser.max_volts = 0.0;
  EXPECT_NE(CheckError(laser).find("MemsLaser.max_volts"), std::string::npos);
  laser = DefaultLaser();
  laser.max_tilt_rad = Eigen::Vector2d(5.0, 5.0);  // degrees typed as radians
  EXPECT_NE(CheckError(laser).find("MemsLaser.max_tilt_rad"), std::string::npos);
  laser = DefaultLaser();
  laser.saturation = Eigen::Vector2d(0.5, 0.0);
  EXPECT_NE(CheckError(laser).find("MemsLaser.saturation"), std::string::npos);
  laser = DefaultLaser();
  laser.lens_gain = 0.5;
  EXPECT_NE(CheckError(laser).find("MemsLaser.lens_gain"), std::string::npos);
  laser = DefaultLaser();
  laser.emitter_direction_C *= 1.01;
  EXPECT_NE(CheckError(laser).find("MemsLaser.emitter_direction_C"), std::string::npos);
  laser = DefaultLaser();
  laser.T_C_Lens.linear() *= 2.0;
  EXPECT_NE(CheckError(laser).find("MemsLaser.T_C_Lens"), std::string::npos);
  // Valid fields, but the emitter shines away from the mirror.
  laser = DefaultLaser();
  laser.emitter_direction_C = -laser.emitter_direction_C;
  EXPECT_NE(CheckError(laser).find("does not reach the water (behind)"), std::string::npos)
      << CheckError(laser);
}

}  // namespace
}  // namespace uwscan::scanner
