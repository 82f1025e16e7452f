#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "mapping/inspection/camera_frames.hpp"
#include "scanner/acquisition/frame_source.hpp"

// The loop that reads a camera until told to stop: the same for `acquire`, `inspect` and the ROS
// node. It reports through values and callbacks; it prints nothing.
namespace uwscan::mapping {

struct ReadLimits {
  std::int64_t frames = 0;  // stop after this many decoded frames (0: no limit)
  double seconds = 0.0;     // stop after this long (0: no limit)
};

struct ReadSummary {
  std::int64_t frames = 0;  // decoded and handed on
  std::int64_t peaks = 0;
  std::int64_t undecodable = 0;
  double seconds = 0.0;  // since the camera started
  scanner::acquisition::FrameSourceStatistics source;
};

struct ReadCallbacks {
  // Every decoded frame, with the camera's frame (for its timestamps).
  std::function<void(FrameRecord&&, const scanner::acquisition::AcquiredFrame&)> consume;
  // About once a second; may be empty.
  std::function<void(const ReadSummary&, double now_s)> status;
  // A camera gap (the watchdog reopened a silent camera), once it ended, and at the end each
  // one that had not; may be empty.
  std::function<void(const scanner::acquisition::CameraGap&)> gap;
  // Polled between frames: true stops the loop.
  std::function<bool()> stop_requested;
};

// Starts the camera and hands every decoded frame on until the limits are reached or a stop is
// requested. Software trigger mode: triggers one frame at a time. Stops the camera before it
// returns.
ReadSummary ReadFrames(scanner::acquisition::FrameSource& source, CameraFrameDecoder& decoder,
                       const ReadLimits& limits, const ReadCallbacks& callbacks);

}  // namespace uwscan::mapping
