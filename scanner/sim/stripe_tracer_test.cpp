#include "scanner/sim/stripe_tracer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "scanner/sim/imr_objects.hpp"

namespace uwscan::scanner::sim {
namespace {

RefractiveCamera AirCamera() {
  RefractiveCamera c;
  c.camera.width_px = 2048;
  c.camera.height_px = 1088;
  c.camera.fx_px = c.camera.fy_px = 1750.0;
  c.camera.cx_px = 1023.5;
  c.camera.cy_px = 543.5;
  c.viewport.normal = Eigen::Vector3d::UnitZ();
  c.viewport.distance_m = 0.03;
  c.viewport.thickness_m = 0.01;
  c.viewport.n_glass = c.viewport.n_water = 1.0;
  return c;
}

std::vector<SceneObject> Wall(double depth_m) {
  SceneObject wall;
  wall.name = "wall";
  wall.shape = ObjectShape::kPlane;
  wall.mesh = MakeRectangle(4.0, 4.0);
  wall.T_W_O.translation() = Eigen::Vector3d(0, 0, depth_m);
  return {wall};
}

// A laser that sweeps the wall from top to bottom, very fast around s = 0.5: the stripe's image
// jumps hundreds of pixels between neighbouring samples on one continuous surface.
LaserPath SteepPath() {
  LaserPath path;
  path.ray_in_water_C = [](double s) {
    const Eigen::Vector3d target(0.05, 0.25 * std::tanh(40.0 * (s - 0.5)), 1.0);
    const Eigen::Vector3d origin(0.3, 0.0, 0.0);
    return RayTrace{HitStatus::kHit, Ray{origin, (target - origin).normalized()}};
  };
  path.s_begin = 0.0;
  path.s_end = 1.0;
  path.samples = 65;
  return path;
}

TEST(StripeTracer, EveryRowOnceThroughJumpsOnOneSurface) {
  const RefractiveCamera camera = AirCamera();
  const RayCaster caster(Wall(1.0));
  const StripeTracer tracer(camera, caster, StripeTraceOptions{});
  const std::vector<TracedPeak> peaks = tracer.Trace(SteepPath(), Eigen::Isometry3d::Identity());
  std::map<int, int> per_row;
  for (const TracedPeak& p : peaks) {
    ++per_row[static_cast<int>(p.px.y())];
    // Exact: the spot projects onto its pixel.
    const std::optional<Eigen::Vector2d> px = camera.ProjectPointInWater(p.p_W);
    ASSERT_TRUE(px);
    EXPECT_LT((*px - p.px).norm(), 1e-6);
  }
  // The stripe runs from y = -0.25 to +0.25 m at 1 m: about rows 106 to 981, each once.
  const int first = per_row.begin()->first, last = per_row.rbegin()->first;
  EXPECT_LT(first, 120);
  EXPECT_GT(last, 960);
  for (int row = first; row <= last; ++row) EXPECT_EQ(per_row[row], 1) << "row " << row;
}

TEST(StripeTracer, AStripeEndsAtTheEdgeOfItsSurface) {
  // A narrow board: the rows end where the board ends, to the row, not a sample short.
  SceneObject board;
  board.name = "board";
  board.shape = ObjectShape::kPlane;
  board.mesh = MakeRectangle(1.0, 0.1);  // y from -0.05 to 0.05 m at 1 m: rows 456 to 631
  board.T_W_O.translation() = Eigen::Vector3d(0, 0, 1.0);
  const RefractiveCamera camera = AirCamera();
  const RayCaster caster({board});
  const StripeTracer tracer(camera, caster, StripeTraceOptions{});
  LaserPath path = SteepPath();
  path.ray_in_water_C = [](double s) {
    const Eigen::Vector3d target(0.05, -0.3 + 0.6 * s, 1.0);
    const Eigen::Vector3d origin(0.3, 0.0, 0.0);
    return RayTrace{HitStatus::kHit, Ray{origin, (target - origin).normalized()}};
  };
  const std::vector<TracedPeak> peaks = tracer.Trace(path, Eigen::Isometry3d::Identity());
  ASSERT_FALSE(peaks.empty());
  // Board edges at v = 543.5 -+ 1750 * 0.05 = 456.0 and 631.0: every row centre inside.
  EXPECT_EQ(peaks.front().px.y(), 456.0);
  EXPECT_EQ(peaks.back().px.y(), 631.0);
  EXPECT_EQ(peaks.size(), 176u);
}

}  // namespace
}  // namespace uwscan::scanner::sim
