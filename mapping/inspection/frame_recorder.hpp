#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "mapping/log/dive_log.hpp"

namespace uwscan::mapping {

struct FrameRecorderStatistics {
  std::int64_t frames_written = 0;
  std::int64_t navigation_written = 0;
  std::size_t queued_bytes = 0;      // frames waiting for the disk now
  std::size_t max_queued_bytes = 0;  // the most that ever waited
  double blocked_s = 0.0;            // time Push() waited for room (the disk was behind)
};

// Records frames into a dive log on its own thread, so that a slow disk does not hold up the
// camera. Push() queues a frame and returns at once while the queue holds less than
// `max_queue_bytes` (a frame counts its peaks and image bytes); when it is full, Push() waits
// for the writer: no frame handed to the recorder is ever dropped. What happens upstream while
// Push() waits is the caller's: a camera reader stops reading, its driver's buffers fill up and
// the camera's next frames are lost (and counted from their ids). Every frame is one committed
// transaction (DiveLogWriter). Not thread-safe on the calling side: one thread pushes.
class FrameRecorder {
 public:
  // Takes over `writer`. Throws uwscan::Error when max_queue_bytes is 0.
  FrameRecorder(DiveLogWriter writer, std::size_t max_queue_bytes);
  ~FrameRecorder();  // Finish(), errors swallowed (call Finish() to see them)
  FrameRecorder(const FrameRecorder&) = delete;
  FrameRecorder& operator=(const FrameRecorder&) = delete;

  // Queues a frame (waits while the queue is full). Throws the writer's uwscan::Error when an
  // earlier frame could not be written.
  void Push(FrameRecord frame);
  // Queues a navigation sample (small: it never waits for room). Throws like Push().
  void PushNavigation(const NavigationRecord& record);
  // Writes every queued frame, stops the writer thread and returns. Throws like Push().
  void Finish();
  FrameRecorderStatistics statistics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::mapping
