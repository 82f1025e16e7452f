#include "apps/bench/soak_bench_command.hpp"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/scanner/camera_frames.hpp"
#include "bench/scratch_folder.hpp"
#include "mapping/inspection/live_inspection.hpp"
#include "scanner/acquisition/fake_camera.hpp"
#include "scanner/acquisition/frame_source.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/resident_memory.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::app {
namespace {

namespace acq = scanner::acquisition;

constexpr double kSeedCameraFps = 339.0;

struct SoakArgs {
  double minutes = 30.0;
  std::string scene;  // empty: scenes/default.yaml in DataFolder()
  std::string json;
};

struct Minute {
  std::int64_t frames = 0;     // received in the minute
  std::int64_t lost = 0;       // lost by the camera link in the minute
  std::int64_t skipped = 0;    // pushed out of the live queue in the minute
  std::int64_t rss_bytes = 0;  // at the minute's end
  double latency_p95_s = 0.0;  // receive to points in the map, frames mapped in the minute
  double latency_max_s = 0.0;
};

double UnixSeconds() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The latencies of the frames mapped since the last call, handed over from the mapping thread.
class LatencyBox {
 public:
  void Add(double latency_s) {
    const std::lock_guard<std::mutex> lock(mutex_);
    latencies_.push_back(latency_s);
  }
  std::vector<double> Take() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(latencies_, {});
  }

 private:
  std::mutex mutex_;
  std::vector<double> latencies_;
};

void CloseMinute(std::vector<double> latencies, const acq::FrameSourceStatistics& link,
                 const mapping::InspectionStatistics& inspection, Minute* previous_totals,
                 std::vector<Minute>* minutes) {
  Minute m;
  m.frames = inspection.frames_received - previous_totals->frames;
  m.lost = link.lost_frames - previous_totals->lost;
  m.skipped = inspection.frames_skipped - previous_totals->skipped;
  m.rss_bytes = ResidentBytes().value_or(0);
  if (!latencies.empty()) {
    std::sort(latencies.begin(), latencies.end());
    m.latency_p95_s =
        latencies[static_cast<size_t>(std::ceil(0.95 * static_cast<double>(latencies.size())) - 1)];
    m.latency_max_s = latencies.back();
  }
  *previous_totals = {inspection.frames_received, link.lost_frames, inspection.frames_skipped};
  minutes->push_back(m);
  std::printf(
      "minute %3zu: %lld frames, %lld lost, %lld skipped, %.0f MB resident, latency p95 "
      "%.1f ms (max %.1f)\n",
      minutes->size(), static_cast<long long>(m.frames), static_cast<long long>(m.lost),
      static_cast<long long>(m.skipped), static_cast<double>(m.rss_bytes) / 1e6,
      m.latency_p95_s * 1e3, m.latency_max_s * 1e3);
  std::fflush(stdout);
}

nlohmann::json MinuteJson(const Minute& m) {
  return {{"frames", m.frames},
          {"frames_lost", m.lost},
          {"frames_skipped", m.skipped},
          {"rss_bytes", m.rss_bytes},
          {"latency_p95_s", m.latency_p95_s},
          {"latency_max_s", m.latency_max_s}};
}

void WriteSoakJson(const std::string& path, const SoakArgs& a, const std::vector<Minute>& minutes,
                   const mapping::InspectionStatistics& s) {
  std::int64_t lost = 0;
  nlohmann::json per_minute = nlohmann::json::array();
  for (const Minute& m : minutes) {
    lost += m.lost;
    per_minute.push_back(MinuteJson(m));
  }
  WriteJsonFile(
      path,
      {{"minutes", a.minutes},
       {"frames_per_s_asked", kSeedCameraFps},
       {"frames", s.frames_received},
       {"frames_lost", lost},
       {"frames_logged", s.frames_logged},
       {"frames_mapped", s.frames_mapped},
       {"frames_skipped", s.frames_skipped},
       {"rss_bytes",
        {{"first_minute", minutes.front().rss_bytes}, {"last_minute", minutes.back().rss_bytes}}},
       {"latency_p95_s",
        {{"first_minute", minutes.front().latency_p95_s},
         {"last_minute", minutes.back().latency_p95_s}}},
       {"latency_measured", "host receive to points in the live map"},
       {"per_minute", per_minute}});
}

void RunSoak(SoakArgs a) {
  if (!(a.minutes >= 1.0 && a.minutes <= 24.0 * 60.0))
    throw Error("--minutes must be in [1, 1440]");
  if (a.scene.empty()) a.scene = (DataFolder() / "scenes" / "default.yaml").string();
  // A private network namespace, as bench acquisition: nothing leaves the machine. Must come
  // before any thread is started.
  if (unshare(CLONE_NEWNET) == 0 && std::system("ip link set lo up") != 0)
    throw Error("bench soak: cannot bring lo up in the private network namespace");
  const scanner::sim::Simulator simulator(scanner::sim::LoadScene(a.scene));
  acq::FakeCameraOptions camera_options;
  camera_options.mode = acq::FakeCameraMode::kProfile;
  camera_options.frame_rate_hz = kSeedCameraFps;
  acq::FakeCamera camera(simulator, camera_options);
  acq::CameraSettings settings;
  settings.buffers = 256;
  acq::FrameSource source(settings);
  CameraArgs camera_args;
  camera_args.camera = settings.address;
  camera_args.scene = a.scene;
  const AcquisitionContext context = MakeContext(camera_args, source.payload(), "bench soak");
  CameraFrameDecoder decoder(source.payload(), context, false);
  bench::ScratchFolder scratch("bench-soak");
  mapping::InspectionOptions options;
  options.mapper.spill_folder = scratch.path();
  options.table_cache = TableCache();
  LatencyBox latencies;
  mapping::LiveInspection inspection(
      context.header, scratch.path() / "soak.db", context.T_V_C, mapping::NavigationNoise{},
      options,
      [&](const mapping::MappedFrame& f) { latencies.Add(UnixSeconds() - f.receive_time_s); });
  std::printf("bench soak: inspect on the fake camera, profile mode, %.0f frames/s, %.0f minutes\n",
              kSeedCameraFps, a.minutes);
  std::vector<Minute> minutes;
  Minute totals;
  source.Start();
  while (source.ElapsedSeconds() < 60.0 * a.minutes) {
    if (std::optional<acq::AcquiredFrame> frame = source.Next(std::chrono::milliseconds(100))) {
      if (std::optional<mapping::FrameRecord> record = decoder.Decode(*frame))
        inspection.Push(ToInspectionFrame(std::move(*record), *frame));
    }
    if (source.ElapsedSeconds() >= 60.0 * static_cast<double>(minutes.size() + 1))
      CloseMinute(latencies.Take(), source.statistics(), inspection.statistics(), &totals,
                  &minutes);
  }
  source.Stop();
  const mapping::InspectionStatistics s = inspection.Finish().statistics;
  if (minutes.empty()) throw Error("bench soak: no minute completed");
  std::printf("frames %lld (logged %lld, mapped %lld, skipped %lld), lost on the link %lld\n",
              static_cast<long long>(s.frames_received), static_cast<long long>(s.frames_logged),
              static_cast<long long>(s.frames_mapped), static_cast<long long>(s.frames_skipped),
              static_cast<long long>(source.statistics().lost_frames));
  if (!a.json.empty()) WriteSoakJson(a.json, a, minutes, s);
}

}  // namespace

void AddSoakBenchCommand(CLI::App& bench) {
  auto args = std::make_shared<SoakArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "soak",
      "inspect on the fake camera (profile mode, 339 frames/s, logged and mapped live) for "
      "--minutes: frames lost and skipped, resident memory and latency to the map, minute by "
      "minute");
  cmd->add_option("--minutes", args->minutes, "minutes to run, in [1, 1440]")
      ->capture_default_str();
  cmd->add_option("--scene", args->scene,
                  "scene the fake camera serves (default: scenes/default.yaml in the data folder)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--json", args->json, "write the figures as JSON");
  cmd->callback([args] { RunSoak(*args); });
}

}  // namespace uwscan::app
