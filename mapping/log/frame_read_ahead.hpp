#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "mapping/log/dive_log.hpp"

namespace uwscan::mapping {

// A dive log's frames read on a thread of their own, ahead of whoever maps them, so that SQLite's
// reads and the rows' decoding and checksums overlap the mapping instead of waiting their turn.
// Frames come out in the log's order, as ForEachFrame hands them over (without ground truth). An
// error reading the log comes out of Next() after every frame read before it, as ForEachFrame
// would raise it there.
// The log must not be used by anyone else until this is destroyed.
class FrameReadAhead {
 public:
  // Reads at most max_bytes_ahead of peaks and images (and at least one frame) ahead.
  explicit FrameReadAhead(const DiveLogReader& log, std::size_t max_bytes_ahead = 32u << 20);
  ~FrameReadAhead();  // stops the reading thread and waits for it
  FrameReadAhead(const FrameReadAhead&) = delete;
  FrameReadAhead& operator=(const FrameReadAhead&) = delete;

  // The next frame, nullopt after the last. Throws what reading the log threw.
  std::optional<FrameRecord> Next();

 private:
  void Read(const DiveLogReader& log);
  void Push(const FrameRecord& frame);

  const std::size_t max_bytes_ahead_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<FrameRecord> frames_;
  std::size_t bytes_ahead_ = 0;
  bool finished_ = false;  // the reader handed over its last frame, or failed
  bool stopping_ = false;  // the consumer is gone
  std::exception_ptr failure_;
  std::thread reader_;
};

}  // namespace uwscan::mapping
