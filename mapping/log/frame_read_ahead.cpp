#include "mapping/log/frame_read_ahead.hpp"

#include <Eigen/Core>
#include <utility>

namespace uwscan::mapping {
namespace {

// Thrown inside the reading thread's visitor to leave ForEachFrame when the consumer has gone.
struct Stopped {};

std::size_t BytesOf(const FrameRecord& frame) {
  return sizeof(FrameRecord) + frame.peaks_px.size() * sizeof(Eigen::Vector2d) +
         (frame.image ? frame.image->bytes.size() : 0);
}

}  // namespace

FrameReadAhead::FrameReadAhead(const DiveLogReader& log, std::size_t max_bytes_ahead)
    : max_bytes_ahead_(max_bytes_ahead), reader_([this, &log] { Read(log); }) {}

FrameReadAhead::~FrameReadAhead() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  reader_.join();
}

void FrameReadAhead::Read(const DiveLogReader& log) {
  std::exception_ptr failure;
  try {
    log.ForEachFrame([this](const FrameRecord& frame, const GroundTruthRecord*) { Push(frame); },
                     /*with_truth=*/false);
  } catch (const Stopped&) {
  } catch (...) {
    failure = std::current_exception();
  }
  {
    const std::lock_guard lock(mutex_);
    failure_ = failure;
    finished_ = true;
  }
  changed_.notify_all();
}

void FrameReadAhead::Push(const FrameRecord& frame) {
  const std::size_t bytes = BytesOf(frame);
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] {
      return stopping_ || frames_.empty() || bytes_ahead_ + bytes <= max_bytes_ahead_;
    });
    if (stopping_) throw Stopped{};
    frames_.push_back(frame);
    bytes_ahead_ += bytes;
  }
  changed_.notify_all();
}

std::optional<FrameRecord> FrameReadAhead::Next() {
  std::optional<FrameRecord> next;
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return finished_ || !frames_.empty(); });
    if (frames_.empty()) {
      if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
      return std::nullopt;
    }
    next = std::move(frames_.front());
    frames_.pop_front();
    bytes_ahead_ -= BytesOf(*next);
  }
  changed_.notify_all();
  return next;
}

}  // namespace uwscan::mapping
