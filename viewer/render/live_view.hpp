#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "scanner/common/triangle_mesh.hpp"
#include "viewer/scene/render_options.hpp"

namespace uwscan::viewer {

struct LiveViewOptions {
  RenderOptions render;  // colour, range, point size, EDL, size, up; camera is the first fit
  // Points held at most; the oldest clouds are dropped beyond it, so a long dive cannot exhaust
  // memory. Also the point budget of what is drawn. >= 1.
  std::size_t point_budget = 4'000'000;
  double decay_s = 0.0;    // clouds older than this (their time) are dropped; 0 keeps them all
  double refresh_s = 0.2;  // the GUI thread drains the queue and redraws this often, > 0
  bool offscreen = false;  // no window on screen (screenshots, tests); Run stops on request only
  void Check() const;
};

// One cloud, e.g. a sweep or a frame of a dive, in the world frame.
struct LiveCloud {
  double time_s = 0.0;
  std::vector<Eigen::Vector3d> points_W;
  std::vector<float> error_m;            // empty, or one per point
  std::vector<float> intensity;          // empty, or one per point
  std::vector<std::int32_t> object_ids;  // empty, or one per point
  // Empty, or one per point: signed deviation from a reference, metres (NaN: within the
  // threshold, or no reference surface near).
  std::vector<float> deviation_m;
};

// A pose on a named track ("navigation", "truth", "slam"): drawn as the track's line.
struct LivePose {
  std::string track;
  double time_s = 0.0;
  Eigen::Isometry3d T_W_B = Eigen::Isometry3d::Identity();
};

// A recognised object: its model where it was found, replaced when the same id comes again.
struct LiveObject {
  int id = 0;
  std::string label;
  std::shared_ptr<const scanner::TriangleMesh> mesh;
  Eigen::Isometry3d T_W_O = Eigen::Isometry3d::Identity();
};

struct LiveViewStats {
  std::int64_t clouds_received = 0;
  std::int64_t clouds_dropped = 0;  // by the budget or the decay time
  std::int64_t points_received = 0;
  std::size_t points_held = 0;
  std::int64_t poses_received = 0;
  std::int64_t redraws = 0;  // times the GUI thread redrew new data
};

// A view that other threads feed while a dive goes on. VTK is not thread-safe: producers only
// put data in a queue (Push, any thread, never waiting for a render); the thread that calls
// Run() owns every VTK object and drains the queue on a timer.
class LiveView {
 public:
  // Throws uwscan::Error when an option is invalid.
  explicit LiveView(const LiveViewOptions& options);
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  // Thread-safe. Clouds beyond the budget or the decay time drop the oldest at once, also
  // before the GUI thread has drawn them. Throws uwscan::Error when a per-point array's size
  // does not match the points.
  void Push(LiveCloud cloud);
  void Push(LivePose pose);
  void Push(LiveObject object);

  // Thread-safe: Run() draws what is queued, writes the final screenshot if one was set, and
  // returns.
  void RequestStop();
  // Before Run(): the picture to write when Run() ends on a stop request.
  void SetFinalScreenshot(const std::filesystem::path& png);
  LiveViewStats stats() const;  // thread-safe

  // On the GUI thread: opens the window (offscreen when the options say so), redraws every
  // refresh_s while new data comes, returns when the window is closed or RequestStop() was
  // called. Throws uwscan::Error when there is no X display (before any window opens).
  void Run(const std::string& title);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::viewer
