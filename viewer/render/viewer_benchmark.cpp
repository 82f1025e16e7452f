#include "viewer/render/viewer_benchmark.hpp"

#include <vtkCamera.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <random>
#include <string>

#include "scanner/common/option_checks.hpp"
#include "scanner/common/resident_memory.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/vtk_scene.hpp"

namespace uwscan::viewer {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Resident memory of this process, megabytes (MiB).
double ResidentMb() { return static_cast<double>(ResidentBytes().value_or(0)) / (1024.0 * 1024.0); }

// A rough seabed: a square of `n` points 10 m wide, gentle waves plus uniform noise, 5 m deep.
Scene Seabed(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> noise(-0.02f, 0.02f);
  const std::size_t side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  const float step = 10.0f / static_cast<float>(side);
  CloudLayer layer;
  layer.name = "seabed";
  layer.origin = Eigen::Vector3d(0.0, 0.0, 5.0);
  layer.points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = step * static_cast<float>(i % side) - 5.0f,
                y = step * static_cast<float>(i / side) - 5.0f;
    layer.points.emplace_back(x, y, 0.3f * std::sin(0.7f * x) * std::cos(0.5f * y) + noise(rng));
  }
  Scene scene;
  scene.clouds.push_back(std::move(layer));
  return scene;
}

ViewerBenchRow Measure(std::size_t n, const ViewerBenchOptions& o) {
  ViewerBenchRow row;
  row.points = n;
  const Scene scene = Seabed(n, o.seed);
  row.rss_before_mb = ResidentMb();
  RenderOptions render;
  render.width_px = o.width_px;
  render.height_px = o.height_px;
  render.max_points = n;  // everything drawn: the figure is the renderer's, not the budget's
  render.eye_dome_lighting = o.eye_dome_lighting;

  const Clock::time_point start = Clock::now();
  internal::VtkScene vtk = internal::BuildVtkScene(scene, render);
  vtkSmartPointer<vtkRenderWindow> window = internal::MakeRenderWindow(render, /*offscreen=*/true);
  window->AddRenderer(vtk.renderer);
  internal::ApplyCameraPreset(*vtk.renderer, render.camera, render.up, vtk.fit_bounds);
  window->Render();
  window->WaitForCompletion();
  row.first_picture_s = Since(start);
  row.rss_shown_mb = ResidentMb();

  std::vector<double> frames;
  for (int f = 0; f < o.frames; ++f) {
    vtk.renderer->GetActiveCamera()->Azimuth(5.0);
    const Clock::time_point t = Clock::now();
    window->Render();
    window->WaitForCompletion();
    frames.push_back(Since(t));
  }
  std::sort(frames.begin(), frames.end());
  row.frame_s = frames[frames.size() / 2];
  row.frame_min_s = frames.front();
  return row;
}

}  // namespace

void ViewerBenchOptions::Check() const {
  const OptionChecks check("ViewerBenchOptions");
  check.Require(!point_counts.empty(), "point_counts", "at least one point count", "none");
  for (std::size_t i = 0; i < point_counts.size(); ++i) {
    if (point_counts[i] < 1) {
      check.Fail("point_counts[" + std::to_string(i) + "]", ">= 1",
                 std::to_string(point_counts[i]));
    }
  }
  check.AtLeast("frames", frames, 1);
  check.InRange("width_px", width_px, 16, 8192, Interval::kClosed, "px");
  check.InRange("height_px", height_px, 16, 8192, Interval::kClosed, "px");
}

std::vector<ViewerBenchRow> RunViewerBenchmark(const ViewerBenchOptions& options,
                                               const std::function<void(double)>& progress) {
  options.Check();
  RequireDisplay();
  std::vector<ViewerBenchRow> rows;
  for (std::size_t i = 0; i < options.point_counts.size(); ++i) {
    rows.push_back(Measure(options.point_counts[i], options));
    if (progress) progress(static_cast<double>(i + 1) / options.point_counts.size());
  }
  return rows;
}

}  // namespace uwscan::viewer
