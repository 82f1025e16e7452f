#include "scanner/optics/flat_viewport.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The camera viewport of the default scanner, its normal tilted by `tilt_deg` about an axis
// in the x-y plane at `axis_deg` from x.
FlatViewport TiltedViewport(double tilt_deg, double axis_deg = 90.0) {
  FlatViewport v = DefaultGalvoScannerModel().camera.viewport;
  const Eigen::Vector3d axis(std::cos(axis_deg * kDeg), std::sin(axis_deg * kDeg), 0.0);
  v.normal = Eigen::AngleAxisd(tilt_deg * kDeg, axis) * Eigen::Vector3d::UnitZ();
  return v;
}

// Unit direction at `incidence_deg` from the normal n, azimuth `azimuth_deg` around it.
Eigen::Vector3d DirectionAround(const Eigen::Vector3d& n, double incidence_deg,
                                double azimuth_deg) {
  const Eigen::Vector3d e1 = n.unitOrthogonal();
  const Eigen::Vector3d e2 = n.cross(e1);
  const double a = incidence_deg * kDeg, b = azimuth_deg * kDeg;
  return std::cos(a) * n + std::sin(a) * (std::cos(b) * e1 + std::sin(b) * e2);
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double DistanceToLine(const Eigen::Vector3d& p, const Ray& line) {
  return (p - line.origin).cross(line.direction).norm();
}

TEST(FlatViewportTest, DefaultViewportsPassCheck) {
  EXPECT_NO_THROW(DefaultGalvoScannerModel().camera.viewport.Check());
  EXPECT_NO_THROW(DefaultGalvoScannerModel().laser.viewport.Check());
  FlatViewport v = TiltedViewport(0.0);
  v.normal = Eigen::Vector3d(0.0, 0.0, 2.0);
  EXPECT_THROW(v.Check(), Error);
}

TEST(FlatViewportTest, TraceOutThenTraceInOfTheReversedRayReturnsToTheStartLine) {
  const Eigen::Vector3d start(0.004, -0.007, 0.002);
  for (double tilt_deg : {0.0, 12.0, 30.0}) {
    const FlatViewport viewport = TiltedViewport(tilt_deg, 35.0);
    for (double incidence_deg = 0.0; incidence_deg < 85.0; incidence_deg += 4.9) {
      for (double azimuth_deg : {0.0, 77.0, 190.0, 300.0}) {
        const Eigen::Vector3d d = DirectionAround(viewport.normal, incidence_deg, azimuth_deg);
        const RayTrace out = TraceOut(viewport, Ray{start, d});
        ASSERT_TRUE(out.ok()) << ToString(out.status);
        // The outgoing ray starts on the outer face.
        EXPECT_NEAR(viewport.normal.dot(out.ray.origin), viewport.OuterOffset(), 1e-15);
        for (double range_m : {0.0, 0.3, 4.0}) {
          const Ray back{out.ray.At(range_m), -out.ray.direction};
          const RayTrace in = TraceIn(viewport, back);
          ASSERT_TRUE(in.ok()) << ToString(in.status) << " range " << range_m << " gap "
                               << viewport.normal.dot(back.origin) - viewport.OuterOffset();
          EXPECT_NEAR(viewport.normal.dot(in.ray.origin), viewport.distance_m, 1e-15);
          EXPECT_LT(AngleBetween(in.ray.direction, -d), 1e-14)
              << "tilt " << tilt_deg << " incidence " << incidence_deg;
          EXPECT_LT(DistanceToLine(start, in.ray), 1e-14)
              << "tilt " << tilt_deg << " incidence " << incidence_deg;
        }
      }
    }
  }
}

TEST(FlatViewportTest, WaterDirectionFollowsSnellAcrossParallelFaces) {
  for (double tilt_deg : {0.0, 20.0}) {
    const FlatViewport viewport = TiltedViewport(tilt_deg, 0.0);
    for (double incidence_deg = 0.0; incidence_deg < 89.95; incidence_deg += 0.7) {
      const Eigen::Vector3d d = DirectionAround(viewport.normal, incidence_deg, 40.0);
      const RayTrace out = TraceOut(viewport, Ray{Eigen::Vector3d::Zero(), d});
      ASSERT_TRUE(out.ok()) << ToString(out.status) << " at " << incidence_deg;
      const double sin_air = d.cross(viewport.normal).norm();
      const double sin_water = out.ray.direction.cross(viewport.normal).norm();
      EXPECT_NEAR(viewport.n_air * sin_air, viewport.n_water * sin_water, 1e-14);
      // Same plane of incidence, same side.
      EXPECT_NEAR(out.ray.direction.dot(d.cross(viewport.normal)), 0.0, 1e-14);
      EXPECT_GT(out.ray.direction.dot(viewport.normal), 0.0);
    }
  }
}

TEST(FlatViewportTest, RayParallelToTheFacesIsReportedParallel) {
  const FlatViewport viewport = TiltedViewport(17.0);
  const Eigen::Vector3d along_face = viewport.normal.unitOrthogonal();
  EXPECT_EQ(TraceOut(viewport, Ray{Eigen::Vector3d::Zero(), along_face}).status,
            HitStatus::kParallel);
  const Eigen::Vector3d in_water = viewport.normal * (viewport.OuterOffset() + 0.5);
  EXPECT_EQ(TraceIn(viewport, Ray{in_water, along_face}).status, HitStatus::kParallel);
}

TEST(FlatViewportTest, FacesBehindTheRayAreReportedBehind) {
  const FlatViewport viewport = TiltedViewport(17.0);
  // From inside the housing, looking away from the viewport.
  const Eigen::Vector3d away = DirectionAround(-viewport.normal, 30.0, 10.0);
  EXPECT_EQ(TraceOut(viewport, Ray{Eigen::Vector3d::Zero(), away}).status, HitStatus::kBehind);
  // From the water, looking away from the viewport.
  const Eigen::Vector3d in_water = viewport.normal * (viewport.OuterOffset() + 0.5);
  EXPECT_EQ(TraceIn(viewport, Ray{in_water, DirectionAround(viewport.normal, 20.0, 0.0)}).status,
            HitStatus::kBehind);
  // From beyond the outer face, TraceOut finds the faces behind it.
  EXPECT_EQ(TraceOut(viewport, Ray{in_water, viewport.normal}).status, HitStatus::kBehind);
}

// Water -> glass never reflects totally (1.33 < 1.49), but glass -> air does once
// 1.33 sin(w) > 1: at w = 48.75 deg. Grazing incidence from the water is far beyond that.
TEST(FlatViewportTest, TraceInBeyondTheCriticalAngleReflectsTotally) {
  const FlatViewport viewport = TiltedViewport(10.0);
  const Eigen::Vector3d in_water = viewport.normal * (viewport.OuterOffset() + 0.2);
  const double critical_deg = std::asin(viewport.n_air / viewport.n_water) / kDeg;
  for (double incidence_deg : {critical_deg + 1e-4, 60.0, 80.0, 89.9}) {
    const Eigen::Vector3d d = DirectionAround(-viewport.normal, incidence_deg, 25.0);
    EXPECT_EQ(TraceIn(viewport, Ray{in_water, d}).status, HitStatus::kTotalInternalReflection)
        << incidence_deg;
  }
  const Eigen::Vector3d below = DirectionAround(-viewport.normal, critical_deg - 1e-4, 25.0);
  const RayTrace in = TraceIn(viewport, Ray{in_water, below});
  ASSERT_TRUE(in.ok());
  EXPECT_GT(AngleBetween(in.ray.direction, -viewport.normal), 88.0 * kDeg);  // grazing in air
}

struct InverseCase {
  FlatViewport viewport;
  Eigen::Vector3d center;
  std::string name;
};

// DirectionThroughViewport is the inverse of TraceOut: for a point on a traced water ray it
// recovers the air direction. Measured: max angle error 6e-16 rad up to 89.9 deg incidence,
// at most 11 Newton iterations (the unknown is tan(angle in air), which stays well
// conditioned at grazing angles; its cap is 100).
TEST(FlatViewportTest, DirectionThroughViewportInvertsTraceOut) {
  std::vector<InverseCase> cases;
  for (double tilt_deg : {0.0, 15.0, 35.0}) {
    cases.push_back({TiltedViewport(tilt_deg, 60.0), Eigen::Vector3d::Zero(),
                     "camera viewport tilted " + std::to_string(tilt_deg)});
  }
  // The laser viewport of the default scanner (toed in by 15 deg), seen from the mirror.
  const GalvoScannerModel scanner = DefaultGalvoScannerModel();
  cases.push_back({scanner.laser.viewport, scanner.laser.T_C_M.translation(), "laser viewport"});
  FlatViewport thick = TiltedViewport(25.0, 0.0);
  thick.thickness_m = 0.08;
  thick.n_glass = 1.77;  // sapphire
  cases.push_back({thick, Eigen::Vector3d(0.01, 0.02, -0.01), "thick sapphire"});

  double max_error_rad = 0.0;
  int max_iterations = 0;
  for (const InverseCase& c : cases) {
    ASSERT_NO_THROW(c.viewport.Check());
    for (double incidence_deg :
         {0.0, 1e-7, 0.01, 1.0, 10.0, 25.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.9}) {
      for (double azimuth_deg : {0.0, 45.0, 123.0, 250.0}) {
        const Eigen::Vector3d d = DirectionAround(c.viewport.normal, incidence_deg, azimuth_deg);
        const RayTrace out = TraceOut(c.viewport, Ray{c.center, d});
        ASSERT_TRUE(out.ok());
        for (double range_m : {0.2, 0.5, 1.0, 2.0, 5.0}) {
          const DirectionResult solved =
              DirectionThroughViewport(c.viewport, c.center, out.ray.At(range_m));
          ASSERT_TRUE(solved.ok()) << ToString(solved.status);
          const double error_rad = AngleBetween(solved.direction, d);
          max_error_rad = std::max(max_error_rad, error_rad);
          max_iterations = std::max(max_iterations, solved.iterations);
          EXPECT_NEAR(solved.direction.norm(), 1.0, 1e-15);
          EXPECT_LT(error_rad, 1e-12)
              << c.name << ": incidence " << incidence_deg << " deg, azimuth " << azimuth_deg
              << ", range " << range_m << " m";
        }
      }
    }
  }
  EXPECT_LE(max_iterations, 15);
  std::cout << "[ measured ] DirectionThroughViewport vs TraceOut: max " << max_error_rad
            << " rad, at most " << max_iterations << " iterations\n";
}

TEST(FlatViewportTest, DirectionThroughViewportReportsPointsNotBeyondTheOuterFace) {
  const FlatViewport viewport = TiltedViewport(15.0);
  const Eigen::Vector3d n = viewport.normal;
  const Eigen::Vector3d side = n.unitOrthogonal();
  const Eigen::Vector3d center = Eigen::Vector3d::Zero();
  // Inside the housing, inside the glass, exactly on the outer face, behind the camera.
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.5 * viewport.distance_m * n + 0.1 * side),
        Eigen::Vector3d((viewport.distance_m + 0.5 * viewport.thickness_m) * n + 0.1 * side),
        Eigen::Vector3d(viewport.OuterOffset() * n + 0.1 * side),
        Eigen::Vector3d(-1.0 * n + 0.3 * side)}) {
    EXPECT_EQ(DirectionThroughViewport(viewport, center, p).status, HitStatus::kBehind)
        << p.transpose();
  }
  // A centre outside the housing (beyond the inner face).
  const Eigen::Vector3d outside = (viewport.distance_m + 0.001) * n;
  EXPECT_EQ(DirectionThroughViewport(viewport, outside, n + 0.1 * side).status, HitStatus::kBehind);
}

TEST(FlatViewportTest, DirectionThroughViewportOnTheAxisIsTheNormal) {
  const FlatViewport viewport = TiltedViewport(22.0, 10.0);
  const Eigen::Vector3d center(0.01, -0.005, 0.0);
  for (double range_m : {0.1, 1.0, 30.0}) {
    const DirectionResult solved =
        DirectionThroughViewport(viewport, center, center + range_m * viewport.normal);
    ASSERT_TRUE(solved.ok());
    EXPECT_LT(AngleBetween(solved.direction, viewport.normal), 1e-15);
  }
}

}  // namespace
}  // namespace uwscan::scanner
