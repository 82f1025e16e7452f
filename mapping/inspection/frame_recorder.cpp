#include "mapping/inspection/frame_recorder.hpp"

#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <variant>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

using Record = std::variant<FrameRecord, NavigationRecord>;

std::size_t FrameBytes(const FrameRecord& f) {
  return sizeof(FrameRecord) + f.peaks_px.size() * sizeof(Eigen::Vector2d) +
         (f.image ? f.image->bytes.size() : 0);
}

std::size_t RecordBytes(const Record& r) {
  return std::holds_alternative<FrameRecord>(r) ? FrameBytes(std::get<FrameRecord>(r))
                                                : sizeof(NavigationRecord);
}

}  // namespace

struct FrameRecorder::Impl {
  DiveLogWriter writer;
  std::size_t capacity;
  mutable std::mutex mutex;
  std::condition_variable changed;
  std::deque<Record> queue;  // frames and navigation samples, in the order they came
  FrameRecorderStatistics stats;
  bool finishing = false;
  std::exception_ptr failure;
  std::thread thread;

  Impl(DiveLogWriter w, std::size_t c) : writer(std::move(w)), capacity(c) {}

  void Run() {
    std::unique_lock<std::mutex> lock(mutex);
    while (true) {
      changed.wait(lock, [this] { return !queue.empty() || finishing; });
      if (queue.empty()) return;
      Record record = std::move(queue.front());
      queue.pop_front();
      const std::size_t bytes = RecordBytes(record);
      const bool is_frame = std::holds_alternative<FrameRecord>(record);
      lock.unlock();
      std::exception_ptr error;
      try {
        if (is_frame) {
          writer.AppendFrame(std::get<FrameRecord>(record));
        } else {
          writer.AppendNavigation(std::get<NavigationRecord>(record));
        }
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      stats.queued_bytes -= bytes;
      if (error) {
        failure = error;
        queue.clear();
        stats.queued_bytes = 0;
        changed.notify_all();
        return;
      }
      ++(is_frame ? stats.frames_written : stats.navigation_written);
      changed.notify_all();
    }
  }
};

FrameRecorder::FrameRecorder(DiveLogWriter writer, std::size_t max_queue_bytes) {
  if (max_queue_bytes == 0) throw Error("frame recorder: max_queue_bytes must be > 0");
  impl_ = std::make_unique<Impl>(std::move(writer), max_queue_bytes);
  impl_->thread = std::thread([this] { impl_->Run(); });
}

FrameRecorder::~FrameRecorder() {
  try {
    Finish();
  } catch (...) {
  }
}

void FrameRecorder::Push(FrameRecord frame) {
  Impl& m = *impl_;
  const std::size_t bytes = FrameBytes(frame);
  std::unique_lock<std::mutex> lock(m.mutex);
  if (m.failure) std::rethrow_exception(m.failure);
  if (m.finishing) throw Error("frame recorder: Push() after Finish()");
  // A frame larger than the whole queue still goes in once the queue is empty.
  const auto start = std::chrono::steady_clock::now();
  bool waited = false;
  while (!m.failure && !m.queue.empty() && m.stats.queued_bytes + bytes > m.capacity) {
    waited = true;
    m.changed.wait(lock);
  }
  if (waited)
    m.stats.blocked_s +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (m.failure) std::rethrow_exception(m.failure);
  m.queue.push_back(std::move(frame));
  m.stats.queued_bytes += bytes;
  m.stats.max_queued_bytes = std::max(m.stats.max_queued_bytes, m.stats.queued_bytes);
  m.changed.notify_all();
}

void FrameRecorder::PushNavigation(const NavigationRecord& record) {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.mutex);
  if (m.failure) std::rethrow_exception(m.failure);
  if (m.finishing) throw Error("frame recorder: PushNavigation() after Finish()");
  m.queue.push_back(record);
  m.stats.queued_bytes += sizeof(NavigationRecord);
  m.stats.max_queued_bytes = std::max(m.stats.max_queued_bytes, m.stats.queued_bytes);
  m.changed.notify_all();
}

void FrameRecorder::Finish() {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    m.finishing = true;
  }
  m.changed.notify_all();
  if (m.thread.joinable()) m.thread.join();
  std::lock_guard<std::mutex> lock(m.mutex);
  if (m.failure) std::rethrow_exception(m.failure);
}

FrameRecorderStatistics FrameRecorder::statistics() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace uwscan::mapping
