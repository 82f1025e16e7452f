#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace uwscan::viewer {

struct ViewerBenchOptions {
  std::vector<std::size_t> point_counts = {1'000'000, 5'000'000};  // each >= 1
  int frames = 5;  // frames timed per count after the first picture, >= 1
  int width_px = 1280;
  int height_px = 960;
  bool eye_dome_lighting = false;
  std::uint64_t seed = 1;  // of the synthetic seabed
  void Check() const;
};

struct ViewerBenchRow {
  std::size_t points = 0;
  double first_picture_s = 0.0;  // VTK objects built, window opened, first frame finished
  double frame_s = 0.0;          // median per frame, camera turned 5 deg between frames
  double frame_min_s = 0.0;
  double rss_before_mb = 0.0;  // process resident memory with the scene in uwscan's types
  double rss_shown_mb = 0.0;   // ... and while it is shown (VTK arrays, driver buffers)
  double held_mb() const { return rss_shown_mb - rss_before_mb; }
};

// The time a user waits for the first picture of a cloud and for each frame after it, and the
// memory the view holds, for synthetic seabeds (a rough height field, coloured by height) of
// each point count, rendered offscreen through the same path as `view --screenshot` with no
// point budget. `progress` (optional) receives the fraction done. Throws uwscan::Error when
// there is no X display or an option is invalid.
std::vector<ViewerBenchRow> RunViewerBenchmark(const ViewerBenchOptions& options,
                                               const std::function<void(double)>& progress = {});

}  // namespace uwscan::viewer
