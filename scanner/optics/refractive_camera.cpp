#include "scanner/optics/refractive_camera.hpp"

#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner {

void RefractiveCamera::Check() const {
  camera.Check();
  viewport.Check();
  OptionChecks("RefractiveCamera")
      .GreaterThan("viewport.distance_m", viewport.distance_m, 0.0,
                   "m (else the camera centre is inside the viewport)");
}

RayTrace RefractiveCamera::PixelToRayInWater(const Eigen::Vector2d& uv_px) const {
  const std::optional<Eigen::Vector3d> direction = camera.BackProject(uv_px);
  if (!direction) return RayTrace{HitStatus::kNoIntersection, Ray{}};
  return TraceOut(viewport, Ray{Eigen::Vector3d::Zero(), *direction});
}

std::optional<Eigen::Vector2d> RefractiveCamera::ProjectPointInWater(
    const Eigen::Vector3d& p_C) const {
  const DirectionResult in_air = DirectionThroughViewport(viewport, Eigen::Vector3d::Zero(), p_C);
  if (!in_air.ok() || !(in_air.direction.z() > 1e-12)) return std::nullopt;
  return camera.Project(in_air.direction);
}

}  // namespace uwscan::scanner
