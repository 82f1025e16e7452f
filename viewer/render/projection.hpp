#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace uwscan::viewer {

// Where a world point falls in a picture, in normalised device coordinates (x right, y up, both
// in [-1, 1] across the picture), given the camera's world-to-NDC matrix; std::nullopt when the
// point is behind the camera or outside the picture. The one projection every picture-space
// position (screenshots' pixels, labels' anchors) is derived from.
inline std::optional<Eigen::Vector2d> NdcOf(const Eigen::Matrix4d& ndc_from_world,
                                            const Eigen::Vector3d& p_W) {
  const Eigen::Vector4d clip = ndc_from_world * p_W.homogeneous();
  if (!(clip.w() > 0.0)) return std::nullopt;
  const Eigen::Vector2d ndc = clip.head<2>() / clip.w();
  if (!(ndc.array().abs() <= 1.0).all()) return std::nullopt;  // NaN fails too
  return ndc;
}

}  // namespace uwscan::viewer
