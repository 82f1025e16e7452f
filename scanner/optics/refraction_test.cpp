#include "scanner/optics/refraction.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <numbers>
#include <optional>
#include <random>
#include <utility>

namespace uwscan::scanner {
namespace {

constexpr double kAir = 1.0;
constexpr double kGlass = 1.49;
constexpr double kWater = 1.33;

Eigen::Vector3d RandomUnit(std::mt19937& rng) {
  std::normal_distribution<double> gauss;
  return Eigen::Vector3d{gauss(rng), gauss(rng), gauss(rng)}.normalized();
}

double SinToNormal(const Eigen::Vector3d& d, const Eigen::Vector3d& n) { return d.cross(n).norm(); }

// A unit direction at `angle_rad` from the normal n, heading along n, in the plane of n and t.
Eigen::Vector3d AtAngle(const Eigen::Vector3d& n, const Eigen::Vector3d& t, double angle_rad) {
  return std::cos(angle_rad) * n + std::sin(angle_rad) * t;
}

const std::array<std::pair<double, double>, 6> kMediaPairs = {{{kAir, kGlass},
                                                               {kGlass, kWater},
                                                               {kAir, kWater},
                                                               {kWater, kGlass},
                                                               {kGlass, kAir},
                                                               {kWater, kAir}}};

TEST(RefractionTest, SnellsLawHoldsAndRayStaysInThePlaneOfIncidence) {
  std::mt19937 rng(7);
  int refracted_count = 0;
  for (const auto& [n1, n2] : kMediaPairs) {
    for (int i = 0; i < 2000; ++i) {
      const Eigen::Vector3d n = RandomUnit(rng);
      const Eigen::Vector3d d = RandomUnit(rng);
      const std::optional<Eigen::Vector3d> r = Refract(d, n, n1, n2);
      if (n1 * SinToNormal(d, n) > n2) {  // beyond the critical angle
        EXPECT_FALSE(r.has_value());
        continue;
      }
      ASSERT_TRUE(r.has_value()) << "d " << d.transpose() << " n " << n.transpose();
      ++refracted_count;
      EXPECT_NEAR(r->norm(), 1.0, 1e-15);
      EXPECT_NEAR(n1 * SinToNormal(d, n), n2 * SinToNormal(*r, n), 1e-14);
      // Coplanar with the incident ray and the normal: zero triple product.
      EXPECT_NEAR(r->dot(d.cross(n)), 0.0, 1e-14);
      // Transmitted: it crosses the surface in the same sense as the incident ray, and its
      // tangential component points the same way.
      EXPECT_GE(r->dot(n) * d.dot(n), 0.0);
      EXPECT_GE((*r - r->dot(n) * n).dot(d - d.dot(n) * n), 0.0);
    }
  }
  EXPECT_GT(refracted_count, 8000);  // of 12000; the rest reflect totally
}

TEST(RefractionTest, NormalOrientationDoesNotMatter) {
  std::mt19937 rng(11);
  for (const auto& [n1, n2] : kMediaPairs) {
    for (int i = 0; i < 1000; ++i) {
      const Eigen::Vector3d n = RandomUnit(rng);
      const Eigen::Vector3d d = RandomUnit(rng);
      const std::optional<Eigen::Vector3d> a = Refract(d, n, n1, n2);
      const std::optional<Eigen::Vector3d> b = Refract(d, -n, n1, n2);
      ASSERT_EQ(a.has_value(), b.has_value());
      if (a) {
        EXPECT_LT((*a - *b).norm(), 1e-15);
      }
    }
  }
}

TEST(RefractionTest, NormalIncidencePassesStraight) {
  std::mt19937 rng(13);
  for (const auto& [n1, n2] : kMediaPairs) {
    for (int i = 0; i < 100; ++i) {
      const Eigen::Vector3d n = RandomUnit(rng);
      for (const Eigen::Vector3d& d : {n, Eigen::Vector3d(-n)}) {
        const std::optional<Eigen::Vector3d> r = Refract(d, n, n1, n2);
        ASSERT_TRUE(r.has_value());
        EXPECT_LT((*r - d).norm(), 1e-15);
      }
    }
  }
}

TEST(RefractionTest, TotalInternalReflectionBeyondTheCriticalAngle) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const Eigen::Vector3d t = n.unitOrthogonal();
  const double critical_rad = std::asin(kAir / kWater);

  // Water -> air just beyond the critical angle: nothing is transmitted.
  EXPECT_FALSE(Refract(AtAngle(n, t, critical_rad + 1e-6), n, kWater, kAir).has_value());
  EXPECT_FALSE(Refract(AtAngle(n, t, critical_rad + 0.3), n, kWater, kAir).has_value());
  EXPECT_FALSE(Refract(AtAngle(n, t, 0.5 * std::numbers::pi), n, kWater, kAir).has_value());

  // Just below: a grazing ray. sin(t2) = 1.33 sin(tc - 1e-6), so the ray leaves
  // sqrt(2 * 1.33 * cos(tc) * 1e-6) = 1.33e-3 rad above the surface.
  const Eigen::Vector3d d = AtAngle(n, t, critical_rad - 1e-6);
  const std::optional<Eigen::Vector3d> r = Refract(d, n, kWater, kAir);
  ASSERT_TRUE(r.has_value());
  const double elevation_rad = std::asin(r->dot(n));
  EXPECT_GT(elevation_rad, 0.0);
  EXPECT_NEAR(elevation_rad, std::sqrt(2.0 * kWater * std::cos(critical_rad) * 1e-6), 1e-6);
  EXPECT_NEAR(kWater * SinToNormal(d, n), kAir * SinToNormal(*r, n), 1e-14);
  EXPECT_GT(r->dot(t), 0.999998);

  // Into the denser medium there is no critical angle: grazing incidence refracts to it.
  const std::optional<Eigen::Vector3d> into_water = Refract(t, n, kAir, kWater);
  ASSERT_TRUE(into_water.has_value());
  EXPECT_NEAR(SinToNormal(*into_water, n), kAir / kWater, 1e-15);
}

// Equal indices leave the ray unchanged. Exactly so for the grazing ray the header names; for
// general rays to round-off, which Refract amplifies near grazing incidence because it forms
// cos_t = sqrt(1 - (1 - cos_i^2)): measured up to 1.5e-13 over these random rays (cos_i down
// to ~1e-3), hence the 1e-12 bound.
TEST(RefractionTest, EqualIndicesLeaveTheRayUnchanged) {
  const Eigen::Vector3d grazing(0.6, 0.8, 0.0);
  const std::optional<Eigen::Vector3d> g = Refract(grazing, Eigen::Vector3d::UnitZ(), 1.2, 1.2);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(*g, grazing);

  std::mt19937 rng(17);
  double max_error = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d n = RandomUnit(rng);
    const Eigen::Vector3d d = RandomUnit(rng);
    const std::optional<Eigen::Vector3d> r = Refract(d, n, kWater, kWater);
    ASSERT_TRUE(r.has_value());
    max_error = std::max(max_error, (*r - d).norm());
    EXPECT_LT((*r - d).norm(), 1e-12) << "cos_i " << d.dot(n);
  }
  std::cout << "[ measured ] Refract with n1 = n2: max |r - d| = " << max_error << "\n";
}

TEST(RefractionTest, ReflectPreservesAngleAndLength) {
  std::mt19937 rng(19);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d n = RandomUnit(rng);
    const Eigen::Vector3d d = RandomUnit(rng) * (0.1 + i * 0.01);  // any length
    for (const Eigen::Vector3d& normal : {n, Eigen::Vector3d(-n)}) {
      const Eigen::Vector3d r = Reflect(d, normal);
      EXPECT_NEAR(r.norm(), d.norm(), 1e-15 * d.norm());
      EXPECT_NEAR(r.dot(n), -d.dot(n), 1e-15 * d.norm());        // angle to the normal kept
      EXPECT_LT((r - r.dot(n) * n - (d - d.dot(n) * n)).norm(),  // tangential part unchanged
                1e-14 * d.norm());
      EXPECT_LT((Reflect(r, normal) - d).norm(), 1e-14 * d.norm());  // an involution
    }
  }
}

}  // namespace
}  // namespace uwscan::scanner
