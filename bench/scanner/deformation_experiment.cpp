#include "bench/scanner/deformation_experiment.hpp"

#include <cmath>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/optics/flat_viewport.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::bench {
namespace {

struct FanPoints {
  std::vector<Eigen::Vector3d> points;
  Eigen::Vector3d central_dir;
};

// Fan apex at the origin, viewport normal +z. The fan spreads along y and is tilted about y
// by the incidence angle, so its central ray meets the viewport at exactly that angle.
FanPoints TraceFan(const DeformationOptions& o, const scanner::FlatViewport& viewport,
                   double incidence_rad) {
  const Eigen::Vector3d central(std::sin(incidence_rad), 0.0, std::cos(incidence_rad));
  const Eigen::Vector3d spread = Eigen::Vector3d::UnitY();
  FanPoints fan;
  const double outer_z = viewport.OuterOffset();
  for (int i = 0; i < o.rays; ++i) {
    const double alpha = -0.5 * o.aperture_rad + o.aperture_rad * i / (o.rays - 1);
    const scanner::Ray in_air{Eigen::Vector3d::Zero(),
                              std::cos(alpha) * central + std::sin(alpha) * spread};
    const scanner::RayTrace out = scanner::TraceOut(viewport, in_air);
    if (!out.ok()) throw Error("deformation experiment: a fan ray does not reach the water");
    if (i == o.rays / 2) fan.central_dir = out.ray.direction;
    for (int j = 0; j < o.points_per_ray; ++j) {
      const double distance =
          o.projection_distance_m - (o.points_per_ray - 1 - j) * o.point_spacing_m;
      const double t = (outer_z + distance - out.ray.origin.z()) / out.ray.direction.z();
      fan.points.push_back(out.ray.At(t));
    }
  }
  return fan;
}

}  // namespace

void DeformationOptions::Check() const {
  const OptionChecks check("DeformationOptions");
  check.AtLeast("rays", rays, 3);
  check.InRange("aperture_rad", aperture_rad, 0.0, 2.5, Interval::kOpen, "rad");
  check.AtLeast("points_per_ray", points_per_ray, 2);
  check.GreaterThan("point_spacing_m", point_spacing_m, 0.0, "m");
  const double span_m = (points_per_ray - 1) * point_spacing_m;
  check.Require(projection_distance_m > span_m, "projection_distance_m",
                "> the span of the points (" + OptionValueText(span_m) + " m)",
                projection_distance_m);
  check.AtLeast("incidence_angles", incidence_angles, 1);
  check.InRange("max_incidence_rad", max_incidence_rad, 0.0, 1.2, Interval::kOpenHigh, "rad");
  check.GreaterThan("source_to_viewport_m", source_to_viewport_m, 0.0, "m");
  check.GreaterThan("thickness_m", thickness_m, 0.0, "m");
  cone.Check();
}

std::vector<DeformationRow> RunDeformationExperiment(const DeformationOptions& o,
                                                     const Progress& progress) {
  o.Check();
  scanner::FlatViewport viewport;
  viewport.normal = Eigen::Vector3d::UnitZ();
  viewport.distance_m = o.source_to_viewport_m;
  viewport.thickness_m = o.thickness_m;
  viewport.n_air = o.n_air;
  viewport.n_glass = o.n_glass;
  viewport.n_water = o.n_water;
  viewport.Check();

  std::vector<DeformationRow> rows;
  for (int k = 0; k < o.incidence_angles; ++k) {
    const double incidence =
        o.incidence_angles == 1 ? 0.0 : o.max_incidence_rad * k / (o.incidence_angles - 1);
    const FanPoints fan = TraceFan(o, viewport, incidence);
    const scanner::PlaneFit plane = scanner::FitPlane(fan.points);
    // The apex hint: the fan leaves the glass near the origin's projection on the outer face.
    const Eigen::Vector3d apex_hint(0.0, 0.0, viewport.OuterOffset());
    const scanner::ConeFit cone = scanner::FitCone(fan.points, fan.central_dir, apex_hint, o.cone);
    rows.push_back(DeformationRow{incidence, plane.rms_m, cone.rms_m, cone.converged});
    if (progress) progress("deformation", (k + 1.0) / o.incidence_angles);
  }
  return rows;
}

}  // namespace uwscan::bench
