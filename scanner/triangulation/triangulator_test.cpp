// Triangulation against exact ground truth: points generated on the refracted laser fan,
// seen through the camera viewport, recovered by each method.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "scanner/common/test_cache.hpp"
#include "scanner/triangulation/light_cone.hpp"
#include "scanner/triangulation/light_surface_cache.hpp"
#include "scanner/triangulation/ray_ray_triangulator.hpp"
#include "scanner/triangulation/surface_triangulators.hpp"

namespace uwscan::scanner {
namespace {

// An exact point of the laser fan at a given camera depth.
std::optional<Eigen::Vector3d> FanPoint(const GalvoScannerModel& model, int step,
                                        double fan_angle_rad, double depth_m) {
  const RayTrace ray = model.laser.FanAtStep(step).RayInWater(std::tan(fan_angle_rad));
  if (!ray.ok() || ray.ray.direction.z() <= 0.0) return std::nullopt;
  return ray.ray.At((depth_m - ray.ray.origin.z()) / ray.ray.direction.z());
}

// The exact camera ray in water through a point, whether or not it falls inside the image.
Ray ExactCameraRay(const GalvoScannerModel& model, const Eigen::Vector3d& p_C) {
  const DirectionResult dir =
      DirectionThroughViewport(model.camera.viewport, Eigen::Vector3d::Zero(), p_C);
  EXPECT_TRUE(dir.ok());
  const RayTrace trace =
      TraceOut(model.camera.viewport, Ray{Eigen::Vector3d::Zero(), dir.direction});
  EXPECT_TRUE(trace.ok());
  return trace.ray;
}

class TriangulationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = std::make_unique<GalvoScannerModel>(DefaultGalvoScannerModel());
    rays_ = std::make_shared<const CameraRayTable>(model_->camera, 4);
    // Under CTest each test runs in its own process: the table is fitted by the first and read
    // back by the others, all with the same default thread count. Outside CTest it is fitted here.
    if (const std::optional<std::filesystem::path> folder = test::TestCacheFolder()) {
      surfaces_ =
          LoadOrBuildLightSurfaceTable(model_->laser, LightSurfaceTableOptions{}, *folder).table;
    } else {
      surfaces_ =
          std::make_shared<const LightSurfaceTable>(model_->laser, LightSurfaceTableOptions{});
    }
  }
  static void TearDownTestSuite() {
    model_.reset();
    rays_.reset();
    surfaces_.reset();
  }
  // Visible exact points of a step, with their pixels.
  static void MakeFrame(int step, int count, std::uint64_t seed, std::vector<Eigen::Vector2d>* px,
                        std::vector<Eigen::Vector3d>* truth) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> angle(-0.45, 0.45), depth(0.5, 1.5);
    for (int i = 0; i < 50 * count && std::ssize(*px) < count; ++i) {
      const double fan_angle = angle(rng);
      const std::optional<Eigen::Vector3d> p = FanPoint(*model_, step, fan_angle, depth(rng));
      if (!p) continue;
      const std::optional<Eigen::Vector2d> uv = model_->camera.ProjectPointInWater(*p);
      if (!uv || !model_->camera.camera.InImage(*uv)) continue;
      px->push_back(*uv);
      truth->push_back(*p);
    }
    ASSERT_EQ(std::ssize(*px), count);
  }

  static std::unique_ptr<GalvoScannerModel> model_;
  static std::shared_ptr<const CameraRayTable> rays_;
  static std::shared_ptr<const LightSurfaceTable> surfaces_;
};
std::unique_ptr<GalvoScannerModel> TriangulationTest::model_;
std::shared_ptr<const CameraRayTable> TriangulationTest::rays_;
std::shared_ptr<const LightSurfaceTable> TriangulationTest::surfaces_;

TEST_F(TriangulationTest, RayRayRecoversExactPointsToNumericalPrecision) {
  const RayRayTriangulator ray_ray(*model_);
  double worst = 0.0;
  for (int step : {-100, -60, -20, 0, 35, 70, 100}) {
    std::vector<Eigen::Vector2d> px;
    std::vector<Eigen::Vector3d> truth;
    MakeFrame(step, 200, 7 + step, &px, &truth);
    std::vector<TriangulatedPoint> out(px.size());
    ray_ray.TriangulateFrame(step, px, out);
    for (size_t i = 0; i < px.size(); ++i) {
      ASSERT_TRUE(out[i].ok()) << "step " << step << " point " << i << " "
                               << ToString(out[i].status);
      worst = std::max(worst, (out[i].p_C - truth[i]).norm());
    }
  }
  EXPECT_LT(worst, 1e-9);
}

TEST_F(TriangulationTest, RayRayAtNearAndFarRange) {
  const RayRayTriangulator ray_ray(*model_);
  // 0.2 m and 5 m lie outside the calibrated range and, at 0.2 m, outside the image: the exact
  // method has no range limit, so it must still recover them.
  for (double depth : {0.2, 5.0}) {
    for (int step : {-100, -40, 0, 60}) {
      for (double angle : {-0.3, 0.0, 0.25}) {
        const std::optional<Eigen::Vector3d> p = FanPoint(*model_, step, angle, depth);
        ASSERT_TRUE(p);
        const TriangulatedPoint q = ray_ray.TriangulateRay(step, ExactCameraRay(*model_, *p));
        ASSERT_TRUE(q.ok()) << ToString(q.status);
        EXPECT_LT((q.p_C - *p).norm(), 1e-9 * std::max(1.0, depth)) << depth << " " << step;
      }
    }
  }
}

TEST_F(TriangulationTest, RayConeIsWithinATenthOfAMillimetreOfExact) {
  const RayConeTriangulator ray_cone(rays_, surfaces_);
  double sum = 0.0, worst = 0.0;
  int n = 0;
  for (int step = -100; step <= 100; step += 25) {
    std::vector<Eigen::Vector2d> px;
    std::vector<Eigen::Vector3d> truth;
    MakeFrame(step, 100, 100 + step, &px, &truth);
    std::vector<TriangulatedPoint> out(px.size());
    ray_cone.TriangulateFrame(step, px, out);
    for (size_t i = 0; i < px.size(); ++i) {
      ASSERT_TRUE(out[i].ok()) << ToString(out[i].status);
      const double e = (out[i].p_C - truth[i]).norm();
      sum += e, ++n, worst = std::max(worst, e);
    }
  }
  EXPECT_LT(sum / n, 0.05e-3);  // the seed's mean ray-cone error
  EXPECT_LT(worst, 0.3e-3);
}

TEST_F(TriangulationTest, RayPlaneIsExactWhereTheLaserPlaneContainsTheViewportNormal) {
  // At step 0 the central laser direction is the laser viewport's normal: the fan plane
  // contains the normal, refraction keeps it planar, and ray-plane is exact up to the camera
  // ray table's interpolation (~1e-7 rad).
  const RayPlaneTriangulator ray_plane(rays_, surfaces_);
  std::vector<Eigen::Vector2d> px;
  std::vector<Eigen::Vector3d> truth;
  MakeFrame(0, 200, 3, &px, &truth);
  std::vector<TriangulatedPoint> out(px.size());
  ray_plane.TriangulateFrame(0, px, out);
  for (size_t i = 0; i < px.size(); ++i) {
    ASSERT_TRUE(out[i].ok());
    EXPECT_LT((out[i].p_C - truth[i]).norm(), 5e-6);
  }
  EXPECT_LT(surfaces_->At(0)->plane_rms_m, 1e-9);
}

TEST_F(TriangulationTest, ConeFitsBetterThanPlaneAwayFromNormalIncidence) {
  for (int step : {-100, -50, 50, 100}) {
    const LightSurfaces* s = surfaces_->At(step);
    ASSERT_NE(s, nullptr);
    EXPECT_TRUE(s->cone_converged) << step;
    EXPECT_GT(s->plane_rms_m, 1e-4) << step;  // the fan visibly bends
    EXPECT_LT(s->cone_rms_m, 0.05 * s->plane_rms_m) << step;
  }
}

TEST_F(TriangulationTest, StepOutsideTheSweepIsReportedNotGuessed) {
  const RayPlaneTriangulator ray_plane(rays_, surfaces_);
  const RayConeTriangulator ray_cone(rays_, surfaces_);
  const RayRayTriangulator ray_ray(*model_);
  const std::vector<Eigen::Vector2d> px = {{1000.0, 500.0}, {1200.0, 20.0}};
  for (const Triangulator* t :
       {static_cast<const Triangulator*>(&ray_plane), static_cast<const Triangulator*>(&ray_cone),
        static_cast<const Triangulator*>(&ray_ray)}) {
    std::vector<TriangulatedPoint> out(px.size());
    t->TriangulateFrame(model_->laser.step_max + 1, px, out);
    for (const TriangulatedPoint& p : out) {
      EXPECT_EQ(p.status, HitStatus::kOutsideSurface) << ToString(t->method());
      EXPECT_TRUE(p.p_C.allFinite());
    }
  }
}

TEST_F(TriangulationTest, PixelsOutsideTheImageAreMisses) {
  const RayConeTriangulator ray_cone(rays_, surfaces_);
  const RayPlaneTriangulator ray_plane(rays_, surfaces_);
  const std::vector<Eigen::Vector2d> px = {{-3.0, 10.0}, {10.0, 5000.0}, {std::nan(""), 1.0}};
  std::vector<TriangulatedPoint> out(px.size());
  for (const Triangulator* t : {static_cast<const Triangulator*>(&ray_plane),
                                static_cast<const Triangulator*>(&ray_cone)}) {
    t->TriangulateFrame(0, px, out);
    for (const TriangulatedPoint& p : out) EXPECT_FALSE(p.ok());
  }
}

TEST_F(TriangulationTest, EveryMethodAppliesTheMinimumAngleAlike) {
  // With a minimum angle larger than any real geometry every point is too grazing to trust, for
  // every method: none of them may return a point.
  TriangulationOptions options;
  options.min_angle_rad = 0.99;  // 57 degrees
  const RayPlaneTriangulator ray_plane(rays_, surfaces_, options);
  const RayConeTriangulator ray_cone(rays_, surfaces_, options);
  const RayRayTriangulator ray_ray(*model_, options);
  std::vector<Eigen::Vector2d> px;
  std::vector<Eigen::Vector3d> truth;
  MakeFrame(40, 20, 11, &px, &truth);
  for (const Triangulator* t :
       {static_cast<const Triangulator*>(&ray_plane), static_cast<const Triangulator*>(&ray_cone),
        static_cast<const Triangulator*>(&ray_ray)}) {
    std::vector<TriangulatedPoint> out(px.size());
    t->TriangulateFrame(40, px, out);
    for (const TriangulatedPoint& p : out) {
      EXPECT_EQ(p.status, HitStatus::kParallel) << ToString(t->method());
      EXPECT_EQ(p.p_C, Eigen::Vector3d::Zero()) << ToString(t->method());
    }
  }
  // With the default minimum (0.5 degrees) the same frame triangulates with every method.
  const RayConeTriangulator cone_default(rays_, surfaces_);
  std::vector<TriangulatedPoint> out(px.size());
  cone_default.TriangulateFrame(40, px, out);
  for (const TriangulatedPoint& p : out) EXPECT_TRUE(p.ok()) << ToString(p.status);
}

TEST_F(TriangulationTest, RayConeRejectsACrossingJustBelowTheMinimumAngle) {
  // The angle between each camera ray and the cone at its crossing, from the exact cone normal
  // (finite differences of the ray-cone point over the pixel would be the same to first order):
  // a minimum angle just above it rejects the point, just below keeps it.
  std::vector<Eigen::Vector2d> px;
  std::vector<Eigen::Vector3d> truth;
  MakeFrame(-60, 5, 12, &px, &truth);
  const PreparedCone cone = PrepareCone(surfaces_->At(-60)->cone);
  for (size_t i = 0; i < px.size(); ++i) {
    Ray ray;
    ASSERT_TRUE(rays_->Lookup(px[i].x(), px[i].y(), &ray));
    const RayHit hit = IntersectRayCone(ray, cone);
    ASSERT_TRUE(hit.ok());
    // Normal of F(s) = y^2 - b^2 (z^2 - u^2) at the hit, in {C}.
    const Eigen::Vector3d s = cone.S_C * hit.point + cone.s_origin;
    const Eigen::Vector3d grad_s(cone.b * cone.b * s.x(), s.y(), -cone.b * cone.b * s.z());
    const Eigen::Vector3d normal_C = cone.S_C.transpose() * grad_s;
    const double angle = std::asin(std::abs(normal_C.normalized().dot(ray.direction.normalized())));
    for (const double factor : {0.999, 1.001}) {
      TriangulationOptions options;
      options.min_angle_rad = angle * factor;
      const RayConeTriangulator ray_cone(rays_, surfaces_, options);
      std::vector<TriangulatedPoint> out(1);
      ray_cone.TriangulateFrame(-60, std::span(&px[i], 1), out);
      EXPECT_EQ(out[0].ok(), factor < 1.0) << "point " << i << " at " << angle << " rad";
    }
  }
}

TEST_F(TriangulationTest, NearlyParallelCameraAndLaserRaysAreReported) {
  const RayRayTriangulator ray_ray(*model_);
  // A "camera ray" crossing a laser ray 0.3 m into the water at 1e-4 rad, tilted out of the
  // fan so that it meets the light surface only there: below the 0.5 degree minimum angle.
  const RayTrace laser = model_->laser.FanAtStep(10).RayInWater(0.1);
  ASSERT_TRUE(laser.ok());
  const Eigen::Vector3d tilt = laser.ray.direction.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d direction = (laser.ray.direction + 1e-4 * tilt).normalized();
  const Ray camera_like{laser.ray.At(0.3) - 0.4 * direction, direction};
  const TriangulatedPoint p = ray_ray.TriangulateRay(10, camera_like);
  // Near-parallel lines make the crossing a near double root of the signed distance, so the
  // search may settle on the parallel ray (kParallel) or on a crossing behind the viewport
  // (kBehind): either way a reported miss, never a point.
  EXPECT_TRUE(p.status == HitStatus::kParallel || p.status == HitStatus::kBehind)
      << ToString(p.status);
  EXPECT_TRUE(p.p_C.allFinite());

  // The same crossing at 0.6 degrees is well conditioned enough and is triangulated.
  const Eigen::Vector3d steeper = (laser.ray.direction + 0.0105 * tilt).normalized();
  const TriangulatedPoint q =
      ray_ray.TriangulateRay(10, Ray{laser.ray.At(0.3) - 0.4 * steeper, steeper});
  ASSERT_TRUE(q.ok()) << ToString(q.status);
  EXPECT_LT((q.p_C - laser.ray.At(0.3)).norm(), 1e-9);
}

TEST_F(TriangulationTest, CameraRayMissingTheFanIsOutsideSurface) {
  const RayRayTriangulator ray_ray(*model_);
  // Straight up, far above the fan's top edge.
  const Ray up{Eigen::Vector3d(0.0, 0.0, 0.042), Eigen::Vector3d(0.0, -0.9, 0.1).normalized()};
  const TriangulatedPoint p = ray_ray.TriangulateRay(0, up);
  EXPECT_EQ(p.status, HitStatus::kOutsideSurface) << ToString(p.status);
}

TEST_F(TriangulationTest, CameraRayTableMatchesExactRays) {
  double worst_rad = 0.0, worst_origin_m = 0.0;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.5, 2047.49), v(-0.5, 1087.49);
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector2d px{u(rng), v(rng)};
    Ray table;
    ASSERT_TRUE(rays_->Lookup(px.x(), px.y(), &table));
    const RayTrace exact = model_->camera.PixelToRayInWater(px);
    ASSERT_TRUE(exact.ok());
    worst_rad = std::max(worst_rad, (table.direction.normalized() - exact.ray.direction).norm());
    worst_origin_m = std::max(worst_origin_m, (table.origin - exact.ray.origin).norm());
  }
  EXPECT_LT(worst_rad, 1e-6);
  EXPECT_LT(worst_origin_m, 1e-7);
}

TEST_F(TriangulationTest, ResultsAreIdenticalRunToRunAndForAnyThreadCount) {
  const RayRayTriangulator a(*model_), b(*model_);
  const int threads = omp_get_max_threads();
  // The suite's table was built with `threads` (the default, here or in the process that cached
  // it).
  omp_set_num_threads(threads == 1 ? 2 : 1);
  const LightSurfaceTable again(model_->laser, LightSurfaceTableOptions{});
  omp_set_num_threads(threads);
  for (int step : {-90, 0, 90}) {
    EXPECT_EQ(again.At(step)->cone.a, surfaces_->At(step)->cone.a);
    EXPECT_EQ(again.At(step)->cone.b, surfaces_->At(step)->cone.b);
    std::vector<Eigen::Vector2d> px;
    std::vector<Eigen::Vector3d> truth;
    MakeFrame(step, 50, 9, &px, &truth);
    std::vector<TriangulatedPoint> out_a(px.size()), out_b(px.size());
    a.TriangulateFrame(step, px, out_a);
    b.TriangulateFrame(step, px, out_b);
    for (size_t i = 0; i < px.size(); ++i) EXPECT_EQ(out_a[i].p_C, out_b[i].p_C);
  }
}

TEST(TriangulationMethodTest, NamesRoundTrip) {
  for (TriangulationMethod m : {TriangulationMethod::kRayPlane, TriangulationMethod::kRayCone,
                                TriangulationMethod::kRayRay}) {
    EXPECT_EQ(ParseTriangulationMethod(ToString(m)), m);
  }
  EXPECT_EQ(ParseTriangulationMethod("cone"), TriangulationMethod::kRayCone);
  EXPECT_FALSE(ParseTriangulationMethod("sphere"));
}

}  // namespace
}  // namespace uwscan::scanner
