#include "scanner/triangulation/light_surface_table.hpp"

#include <cmath>
#include <string>
#include <utility>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/parallel_tasks.hpp"

namespace uwscan::scanner {

void LightSurfaceTableOptions::Check() const {
  const OptionChecks check("LightSurfaceTableOptions");
  check.GreaterThan("depth_min_m", depth_min_m, 0.0, "m");
  check.Require(std::isfinite(depth_max_m) && depth_max_m > depth_min_m, "depth_max_m",
                "a finite value > depth_min_m (" + OptionValueText(depth_min_m) + " m)",
                depth_max_m);
  check.AtLeast("rays_per_fan", rays_per_fan, 3);
  check.AtLeast("points_per_ray", points_per_ray, 2);
  cone.Check();
}

FanSamples SampleFan(const LaserFan& fan, double max_fan_tan,
                     const LightSurfaceTableOptions& options) {
  FanSamples samples;
  const RayTrace central = fan.RayInWater(0.0);
  const RayTrace central_air = fan.RayInAir(0.0);
  if (!central.ok() || !central_air.ok()) {
    throw Error(std::string("light surface table: central laser ray does not reach the water (") +
                ToString(central.status) + ")");
  }
  samples.propagation_dir_C = central.ray.direction;
  samples.apex_hint_C = central_air.ray.origin;
  const double max_angle = std::atan(max_fan_tan);
  for (int i = 0; i < options.rays_per_fan; ++i) {
    const double angle = -max_angle + 2.0 * max_angle * i / (options.rays_per_fan - 1);
    const RayTrace trace = fan.RayInWater(std::tan(angle));
    if (!trace.ok() || trace.ray.direction.z() <= 1e-6) continue;
    for (int j = 0; j < options.points_per_ray; ++j) {
      const double depth = options.depth_min_m + (options.depth_max_m - options.depth_min_m) * j /
                                                     (options.points_per_ray - 1);
      const double t = (depth - trace.ray.origin.z()) / trace.ray.direction.z();
      if (t > 0.0) samples.points_C.push_back(trace.ray.At(t));
    }
  }
  if (samples.points_C.size() < 6) {
    throw Error("light surface table: fewer than 6 fan samples in the working range");
  }
  return samples;
}

LightSurfaceTable::LightSurfaceTable(const GalvoLaser& laser,
                                     const LightSurfaceTableOptions& options)
    : step_min_(laser.step_min), step_max_(laser.step_max), has_cones_(options.fit_cones) {
  laser.Check();
  options.Check();
  const int count = step_max_ - step_min_ + 1;
  surfaces_.resize(static_cast<size_t>(count));
  const double max_fan_tan = laser.MaxFanTan();
  RunParallelTasks(count, 0, [&](std::ptrdiff_t i) {
    const FanSamples samples =
        SampleFan(laser.FanAtStep(step_min_ + static_cast<int>(i)), max_fan_tan, options);
    const PlaneFit plane = FitPlane(samples.points_C);
    LightSurfaces& surfaces = surfaces_[static_cast<size_t>(i)];
    surfaces.plane = plane.plane;
    surfaces.plane_rms_m = plane.rms_m;
    if (options.fit_cones) {
      const ConeFit cone =
          FitCone(samples.points_C, samples.propagation_dir_C, samples.apex_hint_C, options.cone);
      surfaces.cone = cone.cone;
      surfaces.cone_rms_m = cone.rms_m;
      surfaces.cone_converged = cone.converged;
    }
  });
}

LightSurfaceTable::LightSurfaceTable(int step_min, std::vector<LightSurfaces> surfaces,
                                     bool has_cones)
    : step_min_(step_min),
      step_max_(step_min + static_cast<int>(surfaces.size()) - 1),
      surfaces_(std::move(surfaces)),
      has_cones_(has_cones) {
  if (surfaces_.empty()) throw Error("light surface table: no mirror steps");
}

}  // namespace uwscan::scanner
