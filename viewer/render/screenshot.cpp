#include "viewer/render/screenshot.hpp"

#include <cmath>

#include "scanner/common/error.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/projection.hpp"
#include "viewer/render/vtk_scene.hpp"

namespace uwscan::viewer {

std::optional<Eigen::Vector2i> PictureInfo::PixelOf(const Eigen::Vector3d& p_W) const {
  const std::optional<Eigen::Vector2d> ndc = NdcOf(ndc_from_world, p_W);
  if (!ndc) return std::nullopt;
  // Rows count from the top; NDC 1 is the far edge of the last pixel, outside it.
  const int column = static_cast<int>(std::floor((ndc->x() + 1.0) * 0.5 * width_px));
  const int row = static_cast<int>(std::floor((1.0 - ndc->y()) * 0.5 * height_px));
  if (column >= width_px || row >= height_px) return std::nullopt;
  return Eigen::Vector2i(column, row);
}

PictureInfo SaveScreenshot(const Scene& scene, const RenderOptions& options,
                           const std::filesystem::path& png_path) {
  options.Check();
  if (scene.empty()) throw Error(png_path.string() + ": nothing to draw");
  RequireDisplay();
  internal::VtkScene vtk = internal::BuildVtkScene(scene, options);
  vtkSmartPointer<vtkRenderWindow> window = internal::MakeRenderWindow(options, /*offscreen=*/true);
  window->AddRenderer(vtk.renderer);
  internal::ApplyCameraPreset(*vtk.renderer, options.camera, options.up, vtk.fit_bounds);
  window->Render();
  internal::WriteWindowPng(*window, png_path);

  PictureInfo info;
  info.width_px = options.width_px;
  info.height_px = options.height_px;
  info.ndc_from_world = internal::NdcFromWorld(*vtk.renderer, vtk.anchor_W);
  info.points_drawn = vtk.points_drawn;
  info.points_total = vtk.points_total;
  info.range = vtk.range;
  return info;
}

}  // namespace uwscan::viewer
