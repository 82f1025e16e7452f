#include "viewer/render/dive_log_follower.hpp"

#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <thread>

#include "mapping/log/dive_log.hpp"
#include "mapping/reconstruction/incremental_reconstruction.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::viewer {
namespace {

using Clock = std::chrono::steady_clock;

LiveCloud ToLiveCloud(mapping::ReconstructedFrame& frame) {
  LiveCloud cloud;
  cloud.time_s = frame.time_s;
  if (!frame.truth.empty()) {
    cloud.error_m.reserve(frame.points.size());
    for (std::size_t i = 0; i < frame.points.size(); ++i) {
      cloud.error_m.push_back(static_cast<float>((frame.points[i] - frame.truth[i]).norm()));
    }
    cloud.object_ids = std::move(frame.object_ids);
  }
  cloud.points_W = std::move(frame.points);
  return cloud;
}

}  // namespace

void FollowOptions::Check() const {
  const OptionChecks check("FollowOptions");
  check.InRange("poll_s", poll_s, 0.0, 60.0, Interval::kOpenLow, "s");
  check.AtLeast("stop_after_frames", stop_after_frames, 0);
  check.NonNegative("timeout_s", timeout_s, "s");
}

struct DiveLogFollower::Impl {
  std::filesystem::path path;
  FollowOptions options;
  LiveView& view;
  std::atomic<bool> quit{false};
  mutable std::mutex mutex;
  FollowStatus status;
  std::thread thread;

  Impl(std::filesystem::path p, const FollowOptions& o, LiveView& v)
      : path(std::move(p)), options(o), view(v) {}

  bool TimedOut(Clock::time_point since) const {
    return options.timeout_s > 0.0 &&
           std::chrono::duration<double>(Clock::now() - since).count() > options.timeout_s;
  }
  void Sleep() const { std::this_thread::sleep_for(std::chrono::duration<double>(options.poll_s)); }

  // The log once it exists and its header is committed; nullopt when told to quit.
  std::optional<mapping::DiveLogReader> Open() {
    const Clock::time_point start = Clock::now();
    std::string last_error = "does not exist";
    while (!quit) {
      if (std::filesystem::exists(path)) {
        try {
          return mapping::DiveLogReader(path);
        } catch (const Error& e) {
          last_error = e.what();  // a writer between creating the file and committing its header
        }
      }
      if (TimedOut(start)) {
        throw Error(path.string() + ": no readable dive log after " +
                    std::to_string(options.timeout_s) + " s (" + last_error + ")");
      }
      Sleep();
    }
    return std::nullopt;
  }

  void Follow() {
    std::optional<mapping::DiveLogReader> log = Open();
    if (!log) return;
    mapping::IncrementalReconstructor reconstructor(*log, options.reconstruction);
    Clock::time_point last_news = Clock::now();
    while (!quit) {
      std::vector<mapping::ReconstructedFrame> frames = reconstructor.Poll();
      for (mapping::ReconstructedFrame& frame : frames) {
        if (reconstructor.world_frame()) {
          view.Push(LivePose{"navigation", frame.time_s, frame.T_out_C});
          if (frame.true_T_W_C) view.Push(LivePose{"truth", frame.time_s, *frame.true_T_W_C});
        }
        const std::size_t n = frame.points.size();
        view.Push(ToLiveCloud(frame));
        const std::lock_guard<std::mutex> lock(mutex);
        ++status.frames;
        status.points += static_cast<std::int64_t>(n);
      }
      if (!frames.empty()) last_news = Clock::now();
      if (options.stop_after_frames > 0 && reconstructor.frames_done() >= options.stop_after_frames)
        return;
      if (TimedOut(last_news)) {
        throw Error(path.string() + ": no new frame for " + std::to_string(options.timeout_s) +
                    " s (" + std::to_string(reconstructor.frames_done()) + " frames so far)");
      }
      if (frames.empty()) Sleep();
    }
  }

  void Run() {
    try {
      Follow();
    } catch (const std::exception& e) {
      const std::lock_guard<std::mutex> lock(mutex);
      status.error = e.what();
    }
    {
      const std::lock_guard<std::mutex> lock(mutex);
      status.finished = true;
    }
    // The follower ended on its own (frames reached, error, timeout): the view has nothing more
    // coming, so it stops too. When the view asked us to quit this is harmless.
    view.RequestStop();
  }
};

DiveLogFollower::DiveLogFollower(const std::filesystem::path& log, const FollowOptions& options,
                                 LiveView& view) {
  options.Check();
  impl_ = std::make_unique<Impl>(log, options, view);
  impl_->thread = std::thread([impl = impl_.get()] { impl->Run(); });
}

DiveLogFollower::~DiveLogFollower() {
  impl_->quit = true;
  if (impl_->thread.joinable()) impl_->thread.join();
}

FollowStatus DiveLogFollower::status() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->status;
}

}  // namespace uwscan::viewer
