#include "apps/bench/acquisition_bench_command.hpp"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/scanner/camera_frames.hpp"
#include "mapping/inspection/live_inspection.hpp"
#include "scanner/acquisition/fake_camera.hpp"
#include "scanner/acquisition/frame_source.hpp"
#include "scanner/common/error.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"
#include "scanner/stripe/stripe_detector.hpp"

namespace uwscan::app {
namespace {

namespace acq = scanner::acquisition;

struct AcquisitionBenchArgs {
  std::string json;
  double seconds = 4.0;
  std::string profile_scene;  // empty: scenes/default.yaml in DataFolder()
  std::string image_scene;    // empty: scenes/camera_image.yaml in DataFolder()
};

struct StreamFigures {
  double requested_fps = 0.0;
  // Rates over the span from the first to the last frame received (the wait for the first frame
  // left out): frames received per second of the host's clock, and frames the camera made per
  // second of its own clock. The fake camera shares this machine's CPUs with the receiver (and
  // the mapper), and its frame clock can fall behind the rate asked of it.
  double camera_frames_per_s = 0.0;
  double frames_per_s = 0.0;
  double frames_per_s_wall = 0.0;  // frames received / seconds from Start(), the wait included
  double mb_per_s = 0.0;
  std::int64_t frames = 0;
  std::int64_t lost_frames = 0;
  double latency_to_peaks_s = 0.0;  // median, capture (camera clock) to peaks on the host
  // With the live map (LiveInspection, fixed scanner): median capture to points in the map,
  // and the frames the mapper took or skipped.
  std::optional<double> latency_to_map_s;
  std::int64_t frames_mapped = 0;
  std::int64_t frames_skipped = 0;
};

std::uint64_t RealTimeNs() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return static_cast<std::uint64_t>(t.tv_sec) * 1000000000ull +
         static_cast<std::uint64_t>(t.tv_nsec);
}

// The first and last frame received (not their pixels: copying those would cost time here).
struct FrameMark {
  std::int64_t frame_number = 0;
  std::uint64_t camera_ns = 0, host_ns = 0;
  std::int64_t session = 0;
};

// What a stream's loop saw: frames received, the first and last, and the latency from capture to
// decoded peaks of each frame with peaks.
struct StreamRead {
  std::int64_t received = 0;
  std::optional<FrameMark> first;
  FrameMark last;
  std::vector<double> latencies_s;
};

// Reads the started `source` for `seconds`, decoding every frame and handing it to `inspection`
// when there is one.
StreamRead ReadStream(acq::FrameSource& source, CameraFrameDecoder& decoder,
                      mapping::LiveInspection* inspection, double seconds) {
  StreamRead read;
  while (source.ElapsedSeconds() < seconds) {
    std::optional<acq::AcquiredFrame> frame = source.Next(std::chrono::milliseconds(100));
    if (!frame) continue;
    ++read.received;
    read.last = {frame->frame_number, frame->camera_timestamp_ns, frame->host_timestamp_ns,
                 frame->session};
    if (!read.first) read.first = read.last;
    std::optional<mapping::FrameRecord> record = decoder.Decode(*frame);
    if (!record) continue;
    if (!record->peaks_px.empty()) {
      read.latencies_s.push_back(
          (static_cast<double>(RealTimeNs()) - static_cast<double>(frame->camera_timestamp_ns)) *
          1e-9);
    }
    if (inspection) inspection->Push(ToInspectionFrame(std::move(*record), *frame));
  }
  return read;
}

// The rates a stream reached: by the camera's clock, by the host's and over the wall time.
StreamFigures RatesOf(StreamRead& read, const acq::FrameSourceStatistics& s, double elapsed_s,
                      double seconds) {
  const FrameMark& last = read.last;
  if (read.received < 2 || last.host_ns <= read.first->host_ns ||
      last.camera_ns <= read.first->camera_ns) {
    throw Error("bench acquisition: fewer than 2 frames received in " + std::to_string(seconds) +
                " s");
  }
  if (last.session != read.first->session) {
    throw Error(
        "bench acquisition: the camera was reopened during the run (it went silent); run again");
  }
  StreamFigures f;
  f.camera_frames_per_s = static_cast<double>(last.frame_number - read.first->frame_number) /
                          (static_cast<double>(last.camera_ns - read.first->camera_ns) * 1e-9);
  f.frames_per_s = static_cast<double>(read.received - 1) /
                   (static_cast<double>(last.host_ns - read.first->host_ns) * 1e-9);
  f.frames = s.frames;
  f.frames_per_s_wall = s.frames / elapsed_s;
  f.mb_per_s = s.frames > 0 ? static_cast<double>(s.bytes) / static_cast<double>(s.frames) *
                                  f.frames_per_s * 1e-6
                            : 0.0;
  f.lost_frames = s.lost_frames;
  std::vector<double>& latencies = read.latencies_s;
  if (!latencies.empty()) {
    std::nth_element(latencies.begin(), latencies.begin() + latencies.size() / 2, latencies.end());
    f.latency_to_peaks_s = latencies[latencies.size() / 2];
  }
  return f;
}

// Streams `seconds` from the fake camera on 127.0.0.1 and decodes (profile) or detects (image)
// every frame, as `acquire` does, without the disk; with `map`, also maps them live as
// `inspect` does (no log), for the latency from capture to points in the map.
StreamFigures Stream(const scanner::sim::Simulator& simulator, const std::string& scene_path,
                     acq::FakeCameraMode mode, double fps, double seconds, bool map) {
  acq::FakeCameraOptions options;
  options.mode = mode;
  options.frame_rate_hz = fps;
  acq::FakeCamera camera(simulator, options);
  acq::CameraSettings settings;
  settings.buffers = 256;
  acq::FrameSource source(settings);
  CameraArgs args;
  args.camera = settings.address;
  args.scene = scene_path;
  const AcquisitionContext context = MakeContext(args, source.payload(), "bench acquisition");
  CameraFrameDecoder decoder(source.payload(), context, false);
  std::unique_ptr<mapping::LiveInspection> inspection;
  if (map) {
    mapping::InspectionOptions inspection_options;
    inspection_options.mapper.threads = 1;
    inspection_options.table_cache = TableCache();
    inspection = std::make_unique<mapping::LiveInspection>(
        context.header, "", context.T_V_C, mapping::NavigationNoise{}, inspection_options);
  }
  source.Start();
  StreamRead read = ReadStream(source, decoder, inspection.get(), seconds);
  const double elapsed = source.ElapsedSeconds();
  source.Stop();
  StreamFigures f = RatesOf(read, source.statistics(), elapsed, seconds);
  f.requested_fps = camera.frame_rate_hz();
  if (inspection) {
    const mapping::InspectionStatistics m = inspection->Finish().statistics;
    if (m.capture_to_map.frames > 0) f.latency_to_map_s = m.capture_to_map.median_s;
    f.frames_mapped = m.frames_mapped;
    f.frames_skipped = m.frames_skipped;
  }
  return f;
}

// Aravis's own arv-camera-test-0.8 on the same fake camera: its mean frames/s after the first
// second (it prints one rate a second).
double PeerFramesPerSecond(const scanner::sim::Simulator& simulator, acq::FakeCameraMode mode,
                           double fps, double seconds) {
  acq::FakeCameraOptions options;
  options.mode = mode;
  options.frame_rate_hz = fps;
  acq::FakeCamera camera(simulator, options);
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.0f", camera.frame_rate_hz());
  const std::string command = "timeout -s INT " +
                              std::to_string(static_cast<int>(std::ceil(seconds)) + 1) +
                              " arv-camera-test-0.8 -n 127.0.0.1 -f " + rate + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr)
    throw Error("bench acquisition: cannot run arv-camera-test-0.8 (package aravis-tools)");
  std::string output;
  char buffer[4096];
  while (std::size_t n = fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, n);
  pclose(pipe);
  const std::regex line(R"((\d+) frames/s)");
  std::vector<double> rates;
  for (auto it = std::sregex_iterator(output.begin(), output.end(), line);
       it != std::sregex_iterator(); ++it) {
    rates.push_back(std::stod((*it)[1].str()));
  }
  if (rates.size() < 2)
    throw Error("bench acquisition: arv-camera-test-0.8 reported no frame rate:\n" + output);
  double sum = 0.0;
  for (std::size_t i = 1; i < rates.size(); ++i) sum += rates[i];
  return sum / static_cast<double>(rates.size() - 1);
}

// latency_s: capture to points in the map when the run mapped, else capture to peaks.
nlohmann::json ToJson(const StreamFigures& f) {
  nlohmann::json j = {{"requested_frames_per_s", f.requested_fps},
                      {"camera_frames_per_s", f.camera_frames_per_s},
                      {"frames_per_s", f.frames_per_s},
                      {"frames_per_s_wall", f.frames_per_s_wall},
                      {"mb_per_s", f.mb_per_s},
                      {"frames", f.frames},
                      {"lost_frames", f.lost_frames},
                      {"latency_s", f.latency_to_map_s.value_or(f.latency_to_peaks_s)},
                      {"latency_to_peaks_s", f.latency_to_peaks_s}};
  if (f.latency_to_map_s) {
    j["latency_to_map_s"] = *f.latency_to_map_s;
    j["frames_mapped"] = f.frames_mapped;
    j["frames_skipped"] = f.frames_skipped;
  }
  return j;
}

void Print(const char* name, const StreamFigures& f) {
  std::printf(
      "%-16s asked %6.0f frames/s, camera made %7.1f: got %7.1f frames/s, %7.2f MB/s, %lld lost of "
      "%lld, "
      "latency to peaks %.2f ms",
      name, f.requested_fps, f.camera_frames_per_s, f.frames_per_s, f.mb_per_s,
      static_cast<long long>(f.lost_frames), static_cast<long long>(f.frames + f.lost_frames),
      f.latency_to_peaks_s * 1e3);
  if (f.latency_to_map_s) {
    std::printf(", to the map %.2f ms (%lld frames mapped, %lld skipped)",
                *f.latency_to_map_s * 1e3, static_cast<long long>(f.frames_mapped),
                static_cast<long long>(f.frames_skipped));
  }
  std::printf("\n");
}

void RunAcquisitionBench(AcquisitionBenchArgs a) {
  if (a.profile_scene.empty())
    a.profile_scene = (DataFolder() / "scenes" / "default.yaml").string();
  if (a.image_scene.empty())
    a.image_scene = (DataFolder() / "scenes" / "camera_image.yaml").string();
  if (!(a.seconds >= 2.0 && a.seconds <= 600.0)) throw Error("--seconds must be in [2, 600]");
  // A private network namespace (root only): nothing leaves the machine and nothing else on
  // this host's loopback competes. Must come before any thread is started.
  bool private_network = false;
  if (unshare(CLONE_NEWNET) == 0) {
    private_network = std::system("ip link set lo up") == 0;
    if (!private_network)
      throw Error("bench acquisition: cannot bring lo up in the private network namespace");
  }
  std::printf("bench acquisition: %s, %.0f s per run\n",
              private_network ? "private network namespace (lo only)"
                              : "this host's loopback (not root: no private namespace)",
              a.seconds);
  const scanner::sim::Scene profile_scene = scanner::sim::LoadScene(a.profile_scene);
  const scanner::sim::Simulator profile_sim(profile_scene);
  const scanner::sim::Scene image_scene = scanner::sim::LoadScene(a.image_scene);
  const scanner::sim::Simulator image_sim(image_scene);

  // The seed camera's rates are mapped live as `inspect` maps them (latency to the map); the
  // ceilings measure reception alone.
  const StreamFigures profile =
      Stream(profile_sim, a.profile_scene, acq::FakeCameraMode::kProfile, 339.0, a.seconds, true);
  Print("profile", profile);
  const StreamFigures ceiling =
      Stream(profile_sim, a.profile_scene, acq::FakeCameraMode::kProfile, 1000.0, a.seconds, false);
  Print("profile ceiling", ceiling);
  const StreamFigures image =
      Stream(image_sim, a.image_scene, acq::FakeCameraMode::kImage, 60.0, a.seconds, true);
  Print("image 2048x1088", image);
  const StreamFigures image_ceiling =
      Stream(image_sim, a.image_scene, acq::FakeCameraMode::kImage, 1000.0, a.seconds, false);
  Print("image ceiling", image_ceiling);
  const double peer_profile =
      PeerFramesPerSecond(profile_sim, acq::FakeCameraMode::kProfile, 1000.0, a.seconds);
  const double peer_image =
      PeerFramesPerSecond(image_sim, acq::FakeCameraMode::kImage, 1000.0, a.seconds);
  std::printf(
      "peer arv-camera-test-0.8 at the ceilings: profile %.1f frames/s (uwscan %.2fx), image %.1f "
      "frames/s "
      "(uwscan %.2fx)\n",
      peer_profile, ceiling.frames_per_s / peer_profile, peer_image,
      image_ceiling.frames_per_s / peer_image);
  std::printf(
      "latency: median, capture (camera clock) to peaks on the host, and to points in the live map "
      "(LiveInspection, fixed scanner, as `uwscan inspect`)\n");
  if (!a.json.empty()) {
    nlohmann::json profile_json = ToJson(profile);
    profile_json["ceiling"] = ToJson(ceiling);
    nlohmann::json image_json = ToJson(image);
    image_json["ceiling"] = ToJson(image_ceiling);
    WriteJsonFile(
        a.json,
        {{"profile", profile_json},
         {"image", image_json},
         {"peer",
          {{"tool", "arv-camera-test-0.8"},
           {"profile_frames_per_s", peer_profile},
           {"image_frames_per_s", peer_image},
           {"profile_ratio", ceiling.frames_per_s / peer_profile},
           {"image_ratio", image_ceiling.frames_per_s / peer_image}}},
         {"rates_measured_over",
          "frames_per_s and mb_per_s: the span from the first to the last frame received (host "
          "clock); camera_frames_per_s: the camera's frame numbers over its own clock in that "
          "span; "
          "frames_per_s_wall: frames / seconds from the start of acquisition"},
         {"latency_measured_to",
          "latency_s: capture (camera clock) to points in the live map (LiveInspection, as `uwscan "
          "inspect`) at 339 and 60 frames/s; ceilings: to peaks on the host (no map)"},
         {"private_network_namespace", private_network},
         {"seconds_per_run", a.seconds}});
  }
}

}  // namespace

void AddAcquisitionBenchCommand(CLI::App& bench) {
  auto args = std::make_shared<AcquisitionBenchArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "acquisition",
      "frames/s, MB/s, lost frames and latency from the GigE Vision fake camera on loopback, "
      "profile and image mode, with arv-camera-test-0.8 as the peer");
  cmd->add_option("--json", args->json, "write the figures as JSON");
  cmd->add_option("--seconds", args->seconds, "seconds per run")->capture_default_str();
  cmd->add_option("--profile-scene", args->profile_scene,
                  "scene served in profile mode (default: scenes/default.yaml in the data folder, "
                  "`uwscan --data-dir`)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--image-scene", args->image_scene,
                  "scene served in image mode, which renders frames (default: "
                  "scenes/camera_image.yaml in the data folder)")
      ->check(CLI::ExistingFile);
  cmd->callback([args] { RunAcquisitionBench(*args); });
}

}  // namespace uwscan::app
