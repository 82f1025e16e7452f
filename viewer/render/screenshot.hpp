#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <optional>

#include "viewer/scene/colour_map.hpp"
#include "viewer/scene/render_options.hpp"
#include "viewer/scene/scene.hpp"

namespace uwscan::viewer {

// What a picture shows and how the world projects into it.
struct PictureInfo {
  int width_px = 0;
  int height_px = 0;
  Eigen::Matrix4d ndc_from_world = Eigen::Matrix4d::Identity();  // the camera, world to NDC
  std::size_t points_drawn = 0;                                  // after the point budget
  std::size_t points_total = 0;
  std::optional<ScalarRange> range;  // the colour map's range (continuous modes)

  // The pixel (column, row from the top-left corner) a world point falls in; std::nullopt when
  // it is behind the camera or outside the picture.
  std::optional<Eigen::Vector2i> PixelOf(const Eigen::Vector3d& p_W) const;
};

// Renders `scene` offscreen (no window shown) with the options' size and camera preset and
// writes an RGB PNG, atomically. The same scene and options give the same bytes on the same
// machine. Throws uwscan::Error when there is no X display (RequireDisplay), the scene is empty,
// an option is invalid, a colour mode has no values in a layer, or the file cannot be written.
PictureInfo SaveScreenshot(const Scene& scene, const RenderOptions& options,
                           const std::filesystem::path& png_path);

}  // namespace uwscan::viewer
