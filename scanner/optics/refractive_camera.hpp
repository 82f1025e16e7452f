#pragma once

#include <Eigen/Core>
#include <optional>

#include "scanner/optics/flat_viewport.hpp"
#include "scanner/optics/pinhole_camera.hpp"

namespace uwscan::scanner {

// A camera in a dry housing looking through a flat viewport; the viewport is expressed in
// the camera frame {C} and the camera centre is the origin of {C}.
struct RefractiveCamera {
  PinholeCamera camera;
  FlatViewport viewport;

  void Check() const;

  // Pixel -> the camera ray in water, starting on the outer face of the viewport.
  RayTrace PixelToRayInWater(const Eigen::Vector2d& uv_px) const;

  // Point in water (in {C}) -> pixel, through the viewport. std::nullopt when the point is
  // not in front of the viewport. The pixel may lie outside the image; check InImage.
  std::optional<Eigen::Vector2d> ProjectPointInWater(const Eigen::Vector3d& p_C) const;
};

}  // namespace uwscan::scanner
