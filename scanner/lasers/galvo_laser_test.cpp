#include "scanner/lasers/galvo_laser.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/optics/refraction.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

GalvoLaser DefaultLaser() { return DefaultGalvoScannerModel().laser; }

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Fan tangents spanning the whole aperture, ends included.
std::vector<double> FanTangents(const GalvoLaser& laser, int count = 41) {
  std::vector<double> tangents;
  for (int i = 0; i < count; ++i) {
    tangents.push_back(laser.MaxFanTan() * (-1.0 + 2.0 * i / (count - 1)));
  }
  return tangents;
}

// Largest distance of the points from their least-squares plane, metres.
double MaxDistanceFromBestPlane(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::Vector3d normal =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  double max_distance = 0.0;
  for (const Eigen::Vector3d& p : points) {
    max_distance = std::max(max_distance, std::abs(normal.dot(p - mean)));
  }
  return max_distance;
}

TEST(GalvoLaserTest, DefaultLaserPassesCheck) { EXPECT_NO_THROW(DefaultLaser().Check()); }

// The default layout: emitter shining along -x_C onto a mirror turned 37.5 deg about y_C, so
// at mirror angle 0 the central ray leaves at 2 * 37.5 = 75 deg from -x_C: 15 deg inwards.
TEST(GalvoLaserTest, CentralRayAtMirrorAngleZeroAimsFifteenDegreesInwards) {
  GalvoLaser laser = DefaultLaser();
  laser.rotation_distance_m = 0.0;
  const RayTrace central = laser.FanAt(0.0).RayInAir(0.0);
  ASSERT_TRUE(central.ok()) << ToString(central.status);
  const Eigen::Vector3d expected(-std::sin(15.0 * kDeg), 0.0, std::cos(15.0 * kDeg));
  EXPECT_LT((central.ray.direction - expected).norm(), 1e-9);
  // With delta = 0 the central ray meets the mirror on the galvanometer axis.
  EXPECT_LT((central.ray.origin - laser.T_C_M.translation()).norm(), 1e-12);

  // The offset delta of the reflecting surface moves the ray, never turns it.
  const RayTrace shifted = DefaultLaser().FanAt(0.0).RayInAir(0.0);
  ASSERT_TRUE(shifted.ok());
  EXPECT_LT((shifted.ray.direction - expected).norm(), 1e-9);
  EXPECT_GT((shifted.ray.origin - central.ray.origin).norm(), 1e-3);
}

// Law of reflection: turning the mirror by theta about its axis (y) turns the reflected ray by
// 2 theta about the same axis.
TEST(GalvoLaserTest, MirrorRotationTurnsTheReflectedRayByTwiceTheAngle) {
  GalvoLaser laser = DefaultLaser();
  laser.rotation_distance_m = 0.0;
  const Eigen::Vector3d axis_C = laser.T_C_M.linear().col(1);
  ASSERT_LT((axis_C - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  const Eigen::Vector3d d0 = laser.FanAt(0.0).RayInAir(0.0).ray.direction;
  for (int step = laser.step_min; step <= laser.step_max; step += 7) {
    const double theta = laser.MirrorAngle(step);
    const RayTrace central = laser.FanAtStep(step).RayInAir(0.0);
    ASSERT_TRUE(central.ok()) << "step " << step;
    const Eigen::Vector3d expected = Eigen::AngleAxisd(2.0 * theta, axis_C) * d0;
    EXPECT_LT(AngleBetween(central.ray.direction, expected), 1e-14) << "step " << step;
    // Still on the axis of the mirror (delta = 0).
    EXPECT_LT((central.ray.origin - laser.T_C_M.translation()).norm(), 1e-12);
  }
}

// After a flat mirror the fan is still a plane: the mirror image of the emitter's plane, which
// passes through the mirror image of the emitter with normal Reflect(z_L, mirror normal).
TEST(GalvoLaserTest, FanRaysInAirLieInOnePlane) {
  const GalvoLaser laser = DefaultLaser();
  const Eigen::Vector3d z_L = laser.T_C_L.linear().col(2);
  for (int step : {laser.step_min, -37, 0, 1, 64, laser.step_max}) {
    const LaserFan fan = laser.FanAtStep(step);
    const Eigen::Vector3d& m = fan.mirror_normal_C;
    const Eigen::Vector3d virtual_emitter =
        fan.origin_C + 2.0 * (fan.mirror_offset_m - m.dot(fan.origin_C)) * m;
    const Eigen::Vector3d plane_normal = Reflect(z_L, m);
    for (double fan_tan : FanTangents(laser)) {
      const RayTrace ray = fan.RayInAir(fan_tan);
      ASSERT_TRUE(ray.ok()) << "step " << step << " tan " << fan_tan;
      EXPECT_NEAR(ray.ray.direction.norm(), 1.0, 1e-15);
      EXPECT_NEAR(plane_normal.dot(ray.ray.direction), 0.0, 1e-12);
      EXPECT_NEAR(plane_normal.dot(ray.ray.origin - virtual_emitter), 0.0, 1e-12);
      EXPECT_NEAR(plane_normal.dot(ray.ray.At(3.0) - virtual_emitter), 0.0, 1e-12);
      // The ray starts on the mirror surface.
      EXPECT_NEAR(m.dot(ray.ray.origin), fan.mirror_offset_m, 1e-15);
    }
  }
}

// After the viewport the fan is a plane only where the laser plane contains the viewport
// normal (here mirror angle 0, where the central ray crosses the viewport at normal incidence):
// elsewhere each ray refracts in its own plane of incidence and the fan bends into the seed's
// elliptic cone. Measured over the full fan, 0.3..3 m along the water rays: 4.4e-16 m off the
// best plane at step 0, 15 mm at step +-50 (central ray at 11.5 deg incidence), 31 mm at
// step +-100 (23 deg).
TEST(GalvoLaserTest, FanRaysInWaterLeaveThePlaneUnlessTheIncidenceIsNormal) {
  const GalvoLaser laser = DefaultLaser();
  for (int step : {0, 50, -50, 100, -100}) {
    const LaserFan fan = laser.FanAtStep(step);
    std::vector<Eigen::Vector3d> points;
    for (double fan_tan : FanTangents(laser)) {
      const RayTrace ray = fan.RayInWater(fan_tan);
      ASSERT_TRUE(ray.ok()) << "step " << step << " tan " << fan_tan;
      for (double range_m : {0.3, 1.0, 3.0}) points.push_back(ray.ray.At(range_m));
    }
    const double off_plane_m = MaxDistanceFromBestPlane(points);
    std::cout << "[ measured ] step " << step << ": fan in water " << off_plane_m
              << " m off its best plane\n";
    if (step == 0) {
      EXPECT_LT(off_plane_m, 1e-12);
    } else {
      EXPECT_GT(off_plane_m, 1e-4) << "step " << step;
    }
  }
}

TEST(GalvoLaserTest, CheckRejectsANonRigidEmitterPose) {
  GalvoLaser laser = DefaultLaser();
  laser.T_C_L.linear() *= 1.01;  // scaled
  try {
    laser.Check();
    FAIL() << "Check() accepted a scaled T_C_L";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("T_C_L"), std::string::npos) << e.what();
  }
  laser = DefaultLaser();
  laser.T_C_L.linear().col(2) *= -1.0;  // a reflection
  EXPECT_THROW(laser.Check(), Error);
  laser = DefaultLaser();
  laser.T_C_L.linear()(0, 1) += 1e-3;  // sheared
  EXPECT_THROW(laser.Check(), Error);
}

TEST(GalvoLaserTest, CheckRejectsAZeroAperture) {
  GalvoLaser laser = DefaultLaser();
  laser.aperture_rad = 0.0;
  try {
    laser.Check();
    FAIL() << "Check() accepted aperture_rad = 0";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("aperture_rad"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::scanner
