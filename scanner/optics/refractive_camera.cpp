#include "scanner/optics/refractive_camera.hpp"

#include "scanner/common/error.hpp"

namespace uwscan::scanner {

void RefractiveCamera::Check() const {
  camera.Check();
  viewport.Check();
  if (!(viewport.distance_m > 0.0)) {
    throw Error("camera viewport: field 'distance_m' must be > 0 (the camera centre is inside)");
  }
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
