#include "mapping/inspection/live_inspection.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <unordered_map>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::mapping {
namespace {

// The host's real-time clock, Unix seconds: the clock capture and receive times are given in.
double NowUnixSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// The latest latencies in a ring (a live figure, bounded memory), plus count and maximum of all.
class LatencyRecorder {
 public:
  void Add(double latency_s) {
    if (ring_.size() < kCapacity) {
      ring_.push_back(latency_s);
    } else {
      ring_[next_] = latency_s;
      next_ = (next_ + 1) % kCapacity;
    }
    ++count_;
    max_s_ = std::max(max_s_, latency_s);
  }
  LatencyFigures Figures() const {
    LatencyFigures f;
    f.frames = count_;
    f.max_s = max_s_;
    if (ring_.empty()) return f;
    std::vector<double> sorted = ring_;
    std::sort(sorted.begin(), sorted.end());
    f.median_s = sorted[sorted.size() / 2];
    f.p95_s = sorted[std::min(sorted.size() - 1, sorted.size() * 95 / 100)];
    return f;
  }

 private:
  static constexpr std::size_t kCapacity = 65536;
  std::vector<double> ring_;
  std::size_t next_ = 0;
  std::int64_t count_ = 0;
  double max_s_ = 0.0;
};

struct FrameTimes {
  std::optional<double> capture_time_s;
  double receive_time_s = 0.0;
};

}  // namespace

void InspectionOptions::Check() const {
  const OptionChecks check("InspectionOptions");
  check.GreaterThan("log_queue_bytes", log_queue_bytes, 0, "bytes");
  check.AtLeast("live_queue_frames", live_queue_frames, 1);
  check.GreaterThan("map_voxel_m", map_voxel_m, 0.0, "m");
  check.InRange("mapper_nice", mapper_nice, 0, 19);
  mapper.Check();
}

struct LiveInspection::Impl {
  InspectionOptions options;
  std::function<void(const MappedFrame&)> on_mapped;
  std::function<void(const Mapper&)> on_submap_closed;
  std::unique_ptr<FrameRecorder> recorder;  // null without a log
  Mapper mapper;                            // mapping thread only (and Finish after it ended)

  mutable std::mutex mutex;
  std::condition_variable changed;
  std::deque<InspectionFrame> live;          // newest frames waiting for the mapper
  std::vector<NavigationRecord> navigation;  // waiting for the mapper
  bool finishing = false;
  bool finished = false;
  std::exception_ptr mapping_failure;
  InspectionStatistics stats;  // counters; log and latency figures are filled in statistics()
  LatencyRecorder capture_latency, receive_latency;
  std::thread thread;

  // Mapping thread only.
  std::unordered_map<std::int64_t, FrameTimes> in_mapper;  // frames given to the mapper, unplaced
  bool mapper_fed = false;
  std::optional<double> last_time_s;
  int last_sweep = 0;
  double time_offset_s = 0.0;
  int sweep_offset = 0;

  Impl(const InspectionOptions& o, const DiveLogHeader& header, const Eigen::Isometry3d& T_V_C,
       const NavigationNoise& noise)
      : options(o),
        mapper(header.scanner, header.scan_pattern, T_V_C, noise, o.mapper, o.table_cache) {}

  void OnPlaced(const FrameRecord& frame, const Eigen::Isometry3d& T_W_C,
                std::span<const Eigen::Vector3d> points) {
    const double now = NowUnixSeconds();
    FrameTimes times;
    if (auto it = in_mapper.find(frame.index); it != in_mapper.end()) {
      times = it->second;
      in_mapper.erase(it);
    }
    if (on_mapped)
      on_mapped(
          MappedFrame{frame.index, frame.time_s, frame.sweep, times.receive_time_s, T_W_C, points});
    std::lock_guard<std::mutex> lock(mutex);
    ++stats.frames_mapped;
    --stats.frames_waiting;
    stats.points_mapped += static_cast<std::int64_t>(points.size());
    if (times.capture_time_s) capture_latency.Add(now - *times.capture_time_s);
    receive_latency.Add(now - times.receive_time_s);
  }

  void OnLeftOut(const FrameRecord& frame) {
    in_mapper.erase(frame.index);
    std::lock_guard<std::mutex> lock(mutex);
    ++stats.frames_without_navigation;
    --stats.frames_waiting;
  }

  // Gives one frame to the mapper. Fixed scanner: the vehicle is at the origin at the frame's
  // time, and a camera whose clock or sweep count went back (it was restarted) is renumbered
  // on, so that the mapper's time and sweeps keep increasing. False when the frame is out of
  // order (navigation mode).
  bool Map(InspectionFrame& frame) {
    FrameRecord& f = frame.record;
    if (options.fixed_scanner) {
      if (last_time_s &&
          (f.time_s + time_offset_s < *last_time_s || f.sweep + sweep_offset < last_sweep)) {
        time_offset_s = *last_time_s - f.time_s;
        sweep_offset = last_sweep + 1 - f.sweep;
        std::lock_guard<std::mutex> lock(mutex);
        ++stats.clock_restarts;
      }
      f.time_s += time_offset_s;
      f.sweep += sweep_offset;
    } else if (last_time_s && f.time_s < *last_time_s) {
      return false;
    }
    last_time_s = f.time_s;
    last_sweep = f.sweep;
    in_mapper[f.index] = FrameTimes{frame.capture_time_s, frame.receive_time_s};
    mapper_fed = true;
    if (options.fixed_scanner) mapper.AddNavigation({f.time_s, Eigen::Isometry3d::Identity()});
    mapper.AddFrame(f);
    return true;
  }

  void Run() {
    // On Linux a thread's nice value is its own (PRIO_PROCESS with its thread id) and the threads
    // it starts inherit it. Being nicer never needs a privilege; failing to be is no error.
    const id_t thread_id = static_cast<id_t>(::gettid());
    errno = 0;
    const int nice_now = ::getpriority(PRIO_PROCESS, thread_id);
    if (errno == 0)
      ::setpriority(PRIO_PROCESS, thread_id, std::min(19, nice_now + options.mapper_nice));
    std::unique_lock<std::mutex> lock(mutex);
    while (true) {
      changed.wait(lock, [this] { return !live.empty() || !navigation.empty() || finishing; });
      if (live.empty() && navigation.empty()) return;  // finishing, and everything mapped
      std::vector<NavigationRecord> records;
      records.swap(navigation);
      std::optional<InspectionFrame> frame;
      if (!live.empty()) {
        frame = std::move(live.front());
        live.pop_front();
      }
      lock.unlock();
      try {
        const int submaps_before = mapper.submap_count();
        for (const NavigationRecord& r : records) mapper.AddNavigation(r);
        const bool mapped = !frame || Map(*frame);
        if (on_submap_closed && mapper.submap_count() > submaps_before) on_submap_closed(mapper);
        lock.lock();
        if (!mapped) {
          ++stats.frames_out_of_order;
          --stats.frames_waiting;
        }
        stats.submaps = mapper.submap_count();
      } catch (...) {
        lock.lock();
        mapping_failure = std::current_exception();
        live.clear();
        changed.notify_all();
        return;
      }
    }
  }

  void RethrowFailure() const {
    if (!mapping_failure) return;
    try {
      std::rethrow_exception(mapping_failure);
    } catch (const std::exception& e) {
      throw Error(std::string("live mapping failed: ") + e.what());
    }
  }
};

LiveInspection::LiveInspection(const DiveLogHeader& header, const std::filesystem::path& log,
                               const Eigen::Isometry3d& T_V_C, const NavigationNoise& noise,
                               const InspectionOptions& options,
                               std::function<void(const MappedFrame&)> on_mapped) {
  options.Check();
  noise.Check();
  InspectionOptions effective = options;
  if (effective.fixed_scanner) effective.mapper.max_loop_candidates = 0;
  effective.mapper.clouds.map_voxel_m = options.map_voxel_m;
  impl_ = std::make_unique<Impl>(effective, header, T_V_C, noise);
  impl_->on_mapped = std::move(on_mapped);
  if (!log.empty()) {
    DiveLogWriter writer(log, header);
    writer.SetVehicleMount(T_V_C);
    impl_->recorder = std::make_unique<FrameRecorder>(std::move(writer), options.log_queue_bytes);
  }
  Impl* m = impl_.get();
  m->mapper.SetFramePlacedCallback(
      [m](const FrameRecord& f, const Eigen::Isometry3d& T_W_C,
          std::span<const Eigen::Vector3d> points) { m->OnPlaced(f, T_W_C, points); });
  m->mapper.SetFrameLeftOutCallback([m](const FrameRecord& f) { m->OnLeftOut(f); });
  m->thread = std::thread([m] { m->Run(); });
}

LiveInspection::~LiveInspection() {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->finishing = true;
    impl_->live.clear();
  }
  impl_->changed.notify_all();
  if (impl_->thread.joinable()) impl_->thread.join();
}

void LiveInspection::Push(InspectionFrame frame) {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    if (m.finishing) throw Error("live inspection: Push() after Finish()");
    m.RethrowFailure();
    frame.record.index = m.stats.frames_received;
  }
  // The log first, and whole (the image too): it may wait for the disk, never drop. The mapper
  // needs the peaks only.
  if (m.recorder) {
    FrameRecord peaks;
    peaks.index = frame.record.index;
    peaks.time_s = frame.record.time_s;
    peaks.command = frame.record.command;
    peaks.sweep = frame.record.sweep;
    peaks.peaks_px = frame.record.peaks_px;
    m.recorder->Push(std::move(frame.record));
    frame.record = std::move(peaks);
  }
  frame.record.image.reset();
  std::lock_guard<std::mutex> lock(m.mutex);
  ++m.stats.frames_received;
  ++m.stats.frames_waiting;
  if (m.live.size() >= static_cast<std::size_t>(m.options.live_queue_frames)) {
    m.live.pop_front();
    ++m.stats.frames_skipped;
    --m.stats.frames_waiting;
  }
  m.live.push_back(std::move(frame));
  m.changed.notify_all();
}

void LiveInspection::AddNavigation(const NavigationRecord& record) {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    if (m.finishing) throw Error("live inspection: AddNavigation() after Finish()");
    m.RethrowFailure();
  }
  if (m.recorder && !m.options.fixed_scanner) m.recorder->PushNavigation(record);
  std::lock_guard<std::mutex> lock(m.mutex);
  m.navigation.push_back(record);
  m.changed.notify_all();
}

void LiveInspection::SetSubmapClosedCallback(std::function<void(const Mapper&)> callback) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->on_submap_closed = std::move(callback);
}

InspectionResult LiveInspection::Finish() {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    if (m.finished) throw Error("live inspection: Finish() called twice");
    m.finishing = true;
    m.finished = true;
  }
  m.changed.notify_all();
  if (m.thread.joinable()) m.thread.join();
  // The log is closed first: whatever happens to the map, every frame received is on disk.
  if (m.recorder) m.recorder->Finish();
  m.RethrowFailure();
  InspectionResult result;
  if (m.mapper_fed) {
    m.mapper.Finish();
    for (int i = 0; i < m.mapper.submap_count(); ++i) {
      result.slam.push_back({m.mapper.submap(i).anchor_time_s, m.mapper.pose(i)});
      result.navigation.push_back({m.mapper.submap(i).anchor_time_s, m.mapper.submap(i).T_W_V_nav});
    }
    result.map = m.mapper.Map(m.options.map_voxel_m);
  }
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    m.stats.submaps = m.mapper.submap_count();
  }
  result.statistics = statistics();
  return result;
}

InspectionStatistics LiveInspection::statistics() const {
  const Impl& m = *impl_;
  InspectionStatistics s;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    s = m.stats;
    s.capture_to_map = m.capture_latency.Figures();
    s.receive_to_map = m.receive_latency.Figures();
  }
  if (m.recorder) {
    s.log = m.recorder->statistics();
    s.frames_logged = s.log.frames_written;
  }
  return s;
}

}  // namespace uwscan::mapping
