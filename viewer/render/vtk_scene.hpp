#pragma once
// Internal to viewer/: the one place that turns uwscan's scene types into VTK objects. Only
// viewer/*.cpp include this header; nothing outside the module sees VTK.

#include <vtkActor.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>

#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "viewer/scene/colour_map.hpp"
#include "viewer/scene/render_options.hpp"
#include "viewer/scene/scene.hpp"

namespace uwscan::viewer::internal {

// A cloud as drawn, with what a pick needs to name one of its points.
struct DrawnCloud {
  vtkSmartPointer<vtkActor> actor;
  const CloudLayer* layer = nullptr;
  std::size_t stride = 1;      // drawn point j is layer point j * stride
  std::vector<float> scalars;  // per drawn point (continuous modes), else empty
};

struct VtkScene {
  vtkSmartPointer<vtkRenderer> renderer;
  // Render coordinates are world coordinates minus the anchor: VTK holds floats.
  Eigen::Vector3d anchor_W = Eigen::Vector3d::Zero();
  std::vector<DrawnCloud> clouds;
  std::optional<ScalarRange> range;  // the colour map's range, continuous modes with points
  std::size_t points_drawn = 0;
  std::size_t points_total = 0;
  // What the camera presets fit: the clouds and meshes when there are any (a vehicle's path
  // a metre above its scan must not shrink the scan), else everything.
  std::optional<std::array<double, 6>> fit_bounds;
};

// Every layer of `scene` as actors in a new renderer (background, colour bar, EDL as the
// options say; camera not yet placed). `scene` must outlive the result (picks point into it).
VtkScene BuildVtkScene(const Scene& scene, const RenderOptions& options);

// Points (render coordinates = origin_render + offsets[j * stride]) with one RGB colour per
// drawn point, as polydata for a point actor.
vtkSmartPointer<vtkPolyData> PointPolyData(const Eigen::Vector3d& origin_render,
                                           const std::vector<Eigen::Vector3f>& offsets,
                                           std::size_t stride, const std::vector<Rgb>& colours);
// A trajectory's line (unlit, exact colour) and a mesh placed in the world, in render
// coordinates (world minus anchor_W).
vtkSmartPointer<vtkActor> TrajectoryActor(const TrajectoryLayer& layer, const Rgb& colour,
                                          const Eigen::Vector3d& anchor_W);
vtkSmartPointer<vtkActor> MeshActor(const MeshLayer& layer, const Rgb& colour,
                                    const Eigen::Vector3d& anchor_W);
// An unlit point actor (vtkPointGaussianMapper drawing plain points): exact colours.
vtkSmartPointer<vtkActor> PointActor(vtkPolyData* points, double point_size_px);
// The scalar bar of `mode`'s colour map (diverging for deviations, else the continuous one)
// over `range`.
vtkSmartPointer<vtkScalarBarActor> ColourBar(const ScalarRange& range, const std::string& title,
                                             ColourMode mode);
void EnableEyeDomeLighting(vtkRenderer& renderer);

// Places the camera for a preset around `bounds` (render coordinates), or everything visible.
void ApplyCameraPreset(vtkRenderer& renderer, CameraPreset preset, const Eigen::Vector3d& up,
                       const std::optional<std::array<double, 6>>& bounds = std::nullopt);
// The union of the actors' bounds; nullopt when none has any.
std::optional<std::array<double, 6>> UnionBounds(const std::vector<vtkActor*>& actors);

// A render window of the options' size, no multisampling (the same input gives the same
// pixels), offscreen when asked. Call RequireDisplay() first.
vtkSmartPointer<vtkRenderWindow> MakeRenderWindow(const RenderOptions& options, bool offscreen);

// Writes what the window shows as an RGB PNG, atomically (temporary file renamed over the
// target). Throws uwscan::Error naming the file when it cannot be written.
void WriteWindowPng(vtkRenderWindow& window, const std::filesystem::path& path);

// World coordinates to normalised device coordinates for the renderer's current camera.
Eigen::Matrix4d NdcFromWorld(vtkRenderer& renderer, const Eigen::Vector3d& anchor_W);

}  // namespace uwscan::viewer::internal
