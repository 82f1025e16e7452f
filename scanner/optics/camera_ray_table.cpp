#include "scanner/optics/camera_ray_table.hpp"

#include <cmath>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {

CameraRayTable::CameraRayTable(const RefractiveCamera& camera, int grid_px)
    : grid_px_(grid_px), inverse_grid_(1.0 / grid_px) {
  if (grid_px < 1) throw Error("camera ray table: grid_px must be >= 1");
  camera.Check();
  const int width = camera.camera.width_px, height = camera.camera.height_px;
  // Nodes at (-0.5 + i * grid) cover the image [-0.5, width - 0.5] plus one cell margin.
  columns_ = width / grid_px + 2;
  rows_ = height / grid_px + 2;
  max_u_ = static_cast<double>(width) * inverse_grid_;
  max_v_ = static_cast<double>(height) * inverse_grid_;
  nodes_.resize(static_cast<size_t>(columns_) * rows_);
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < columns_; ++c) {
      const Eigen::Vector2d uv(-0.5 + c * grid_px, -0.5 + r * grid_px);
      const RayTrace trace = camera.PixelToRayInWater(uv);
      if (!trace.ok()) {
        throw Error("camera ray table: no ray in water for pixel (" + std::to_string(uv.x()) +
                    ", " + std::to_string(uv.y()) + "): " + ToString(trace.status));
      }
      Node& node = nodes_[static_cast<size_t>(r) * columns_ + c];
      for (int k = 0; k < 3; ++k) {
        node.origin[k] = trace.ray.origin[k];
        node.direction[k] = trace.ray.direction[k];
      }
    }
  }
}

}  // namespace uwscan::scanner
