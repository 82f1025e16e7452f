#include "mapping/change/surface_deviation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace uwscan::mapping {
namespace {

// Points of the plane z = height on a 2 mm grid over [x_lo, x_hi] x [-0.05, 0.05] m.
perception::PointCloud Plane(double x_lo, double x_hi, double height_m) {
  std::vector<Eigen::Vector3d> points;
  for (double x = x_lo; x <= x_hi + 1e-9; x += 0.002)
    for (double y = -0.05; y <= 0.05 + 1e-9; y += 0.002) points.emplace_back(x, y, height_m);
  return perception::MakeCloud(points);
}

TEST(MeasureDeviations, ACylinderTheMapCoversOnOneSideOnlyIsNotInspected) {
  // The map ends at x = 0; the reference goes on. Core points every 5 mm across the map's edge.
  const perception::PointCloud map = Plane(-0.1, 0.0, 0.001), reference = Plane(-0.1, 0.1, 0.0);
  CorePoints core;
  for (int k = -6; k <= 6; ++k) {
    core.points_W.emplace_back(0.005 * k, 0.0, 0.0);
    core.normals_W.push_back(Eigen::Vector3d::UnitZ());
  }
  const DeviationOptions options;  // cylinders 15 mm in radius
  const std::vector<CoreDeviation> d =
      MeasureDeviations(map, reference, core, options,
                        [](const Eigen::Vector3d&, const Eigen::Vector3d&) { return 0.0; });
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double x = d[i].point_W.x();
    SCOPED_TRACE("core point at x = " + std::to_string(x));
    // Half of the cross-section or more covered: measured, at the map's true offset.
    if (x <= 0.0) {
      ASSERT_NE(d[i].status, SurfaceStatus::kNotInspected);
      EXPECT_NEAR(d[i].deviation_m, 0.001, 1e-9);
    } else {
      // Only the map's last points, on one side of the line, would speak for the whole
      // footprint: not inspected, though up to x = 15 mm the cylinder holds dozens of them.
      EXPECT_EQ(d[i].status, SurfaceStatus::kNotInspected);
    }
  }
}

}  // namespace
}  // namespace uwscan::mapping
