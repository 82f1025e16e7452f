#pragma once

#include <Eigen/Core>
#include <optional>

namespace uwscan::scanner {

// Pinhole camera with OpenCV's distortion model (k1 k2 p1 p2 k3), frame {C}: x right, y down,
// z forward. Pixel coordinates follow OpenCV: the centre of the top-left pixel is (0, 0).
struct PinholeCamera {
  int width_px = 0;
  int height_px = 0;
  double fx_px = 0.0;  // focal lengths, pixels
  double fy_px = 0.0;
  double cx_px = 0.0;  // principal point, pixels
  double cy_px = 0.0;
  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0, k3 = 0.0;  // OpenCV distortion, unitless

  // Throws uwscan::Error naming the field when a value is not usable.
  void Check() const;

  bool InImage(const Eigen::Vector2d& uv_px) const {
    return uv_px.x() >= -0.5 && uv_px.y() >= -0.5 && uv_px.x() <= width_px - 0.5 &&
           uv_px.y() <= height_px - 0.5;
  }

  // Normalised undistorted (x/z, y/z) -> normalised distorted coordinates (OpenCV's model).
  Eigen::Vector2d Distort(const Eigen::Vector2d& xy) const;

  // Point in {C} (z > 0) -> pixel, as cv::projectPoints with identity pose.
  Eigen::Vector2d Project(const Eigen::Vector3d& p_C) const;

  // Pixel -> normalised undistorted coordinates, inverting Distort by Newton's method to
  // machine precision. std::nullopt when the pixel lies where the distortion model folds
  // over (no unique inverse) or Newton does not converge.
  std::optional<Eigen::Vector2d> Undistort(const Eigen::Vector2d& uv_px) const;

  // Pixel -> unit ray direction in {C} (in the medium the lens sits in, air).
  std::optional<Eigen::Vector3d> BackProject(const Eigen::Vector2d& uv_px) const;
};

}  // namespace uwscan::scanner
