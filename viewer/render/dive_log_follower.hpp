#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "mapping/reconstruction/reconstruction.hpp"
#include "viewer/render/live_view.hpp"

namespace uwscan::viewer {

struct FollowOptions {
  mapping::ReconstructionOptions reconstruction;
  double poll_s = 0.2;  // how often the log is asked for new frames, > 0
  // Stop (and ask the view to stop) once the log holds this many frames; 0: follow until the
  // view is closed.
  std::int64_t stop_after_frames = 0;
  // Give up (an error) when the log has not appeared, or no new frame came, for this long;
  // 0: wait forever.
  double timeout_s = 0.0;
  void Check() const;
};

struct FollowStatus {
  std::int64_t frames = 0;  // frames reconstructed and handed to the view
  std::int64_t points = 0;
  bool finished = false;  // the thread has ended (stop, error or timeout)
  std::string error;      // why it ended, when it failed
};

// A producer thread for a LiveView: waits for the dive log to exist and hold its header (a
// writer may not have created it yet), then hands the view each new frame's points (with error
// and object ids when simulated) and the camera's navigated and true positions, as the writer
// commits them (mapping::IncrementalReconstructor). Failures end the thread, are kept in
// status().error, and stop the view.
class DiveLogFollower {
 public:
  DiveLogFollower(const std::filesystem::path& log, const FollowOptions& options, LiveView& view);
  ~DiveLogFollower();  // stops the thread and waits for it
  DiveLogFollower(const DiveLogFollower&) = delete;
  DiveLogFollower& operator=(const DiveLogFollower&) = delete;

  FollowStatus status() const;  // thread-safe

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::viewer
