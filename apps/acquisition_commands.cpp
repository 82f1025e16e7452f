#include "apps/acquisition_commands.hpp"
#include "apps/text_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "apps/json_output.hpp"
#include "apps/progress_bar.hpp"
#include "mapping/dive_log.hpp"
#include "mapping/frame_recorder.hpp"
#include "scanner/acquisition/fake_camera.hpp"
#include "scanner/acquisition/frame_source.hpp"
#include "scanner/acquisition/mirror_driver.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"
#include "scanner/stripe/stripe_detector.hpp"

namespace uwscan::app {
namespace {

namespace acq = scanner::acquisition;

// SIGINT and SIGTERM ask the running command to stop; the command finishes cleanly.
std::atomic<int> g_stop_signal{0};
void OnStopSignal(int signal) { g_stop_signal.store(signal); }
void InstallStopHandlers() {
  g_stop_signal.store(0);
  struct sigaction action = {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}
bool StopRequested() { return g_stop_signal.load() != 0; }

// --------------------------------------------------------------------------------------------
struct FakeCameraArgs {
  std::string scene;
  std::string address = "127.0.0.1";
  std::string mode = "profile";
  double fps = 0.0;
  double loss = 0.0;
  std::uint64_t seed = 1;
  int peak_rows = 4;
  double seconds = 0.0;
};

void RunFakeCamera(const FakeCameraArgs& a) {
  acq::FakeCameraOptions options;
  options.address = a.address;
  if (a.mode == "image") options.mode = acq::FakeCameraMode::kImage;
  else if (a.mode == "profile") options.mode = acq::FakeCameraMode::kProfile;
  else throw Error("--mode: unknown '" + a.mode + "' (use image or profile)");
  options.frame_rate_hz = a.fps;
  options.loss_ratio = a.loss;
  options.seed = a.seed;
  options.peak_rows = a.peak_rows;
  options.Check();
  InstallStopHandlers();
  const scanner::sim::Scene scene = scanner::sim::LoadScene(a.scene);
  const scanner::sim::Simulator simulator(scene);
  std::unique_ptr<acq::FakeCamera> camera;
  {
    ProgressBar bar;
    camera = std::make_unique<acq::FakeCamera>(simulator, options,
                                               [&bar](double f) { bar.Update("prepare frames", f); });
  }
  std::printf("fake-camera: serving %lld frames of %s (%s scanner, %s mode, %zu-byte payload) at %.1f frames/s on %s"
              "%s; Ctrl-C stops\n",
              static_cast<long long>(simulator.frame_count()), a.scene.c_str(),
              scanner::ToString(scene.scanner.model.kind()), acq::ToString(options.mode),
              camera->payload_bytes(), camera->frame_rate_hz(), a.address.c_str(),
              a.loss > 0.0 ? (", losing " + std::to_string(a.loss) + " of the frames").c_str() : "");
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  while (!StopRequested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (a.seconds > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= a.seconds) {
      break;
    }
  }
  const acq::FakeCameraStatistics s = camera->statistics();
  camera.reset();
  std::printf("fake-camera: stopped; %llu frames sent, %llu withheld (loss), %llu peaks beyond %d per line\n",
              static_cast<unsigned long long>(s.frames_sent), static_cast<unsigned long long>(s.frames_dropped),
              static_cast<unsigned long long>(s.peaks_dropped), a.peak_rows);
}

// --------------------------------------------------------------------------------------------
struct AcquireArgs {
  std::string camera;
  std::string output;
  std::int64_t frames = 0;
  double seconds = 0.0;
  bool images = false;
  bool force = false;
  std::string scene;
  std::string scanner_file;
  std::string receive = "packet";
  std::string trigger = "free";
  std::string pixel_format;
  int packet_size = 0;
  double fps = 0.0;
  double exposure_us = 0.0;
  double gain = -1.0;
  std::vector<int> roi;
  int buffers = 256;
  double queue_mb = 512.0;
  double watchdog_s = 2.0;
  std::string json;
};

// What the log's header says the frames were taken with, and how image frames are searched.
struct AcquisitionContext {
  mapping::DiveLogHeader header;
  scanner::StripeDetectorOptions detector;
};

AcquisitionContext MakeContext(const AcquireArgs& a, const acq::PayloadDescription& payload) {
  AcquisitionContext c;
  c.header.producer = std::string("uwscan acquire ") + UWSCAN_VERSION + " (camera " + a.camera + ", " +
                      payload.vendor + " " + payload.model + ")";
  if (!a.scene.empty()) {
    const scanner::sim::Scene scene = scanner::sim::LoadScene(a.scene);
    const scanner::sim::Simulator simulator(scene);
    c.header.scanner = simulator.scanner();
    c.header.scan_pattern = simulator.scan_pattern();
    c.header.scene_yaml = ReadText(a.scene);
    c.detector = scene.detector;
  } else {
    c.header.scanner = scanner::LoadScanner(a.scanner_file);
    c.header.scan_pattern.kind = c.header.scanner.kind();
    c.detector.axis = payload.profile_layout.axis;
  }
  return c;
}

struct AcquireSummary {
  std::int64_t frames = 0;
  std::int64_t peaks = 0;
  std::int64_t undecodable = 0;
  double seconds = 0.0;
  acq::FrameSourceStatistics source;
  mapping::FrameRecorderStatistics recorder;
  int stop_signal = 0;
};

void PrintStatus(const AcquireSummary& s, double seconds, std::size_t queued_bytes, bool final_line) {
  const double fps = seconds > 0 ? s.frames / seconds : 0.0;
  const double mbps = seconds > 0 ? s.source.bytes / seconds * 1e-6 : 0.0;
  std::fprintf(stderr, "%sacquire: %lld frames, %.1f frames/s, %.2f MB/s, %lld lost, queue %.1f MB%s",
               isatty(2) ? "\r" : "", static_cast<long long>(s.frames), fps, mbps,
               static_cast<long long>(s.source.lost_frames), queued_bytes * 1e-6,
               final_line || !isatty(2) ? "\n" : "   ");
}

void RunAcquire(const AcquireArgs& a) {
  if (a.frames > 0 && a.seconds > 0.0) throw Error("--frames and --seconds: give one of them");
  if (a.scene.empty() == a.scanner_file.empty()) {
    throw Error("give --scene (a simulated camera: the scene's scanner and scan pattern) or --scanner "
                "(the scanner file of a real camera)");
  }
  const std::filesystem::path parent = std::filesystem::path(a.output).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw Error("-o " + a.output + ": folder '" + parent.string() + "' does not exist");
  }
  if (std::filesystem::exists(a.output)) {
    if (!a.force) throw Error(a.output + ": exists (a dive log is never overwritten; use --force)");
    if (!std::filesystem::is_regular_file(a.output)) throw Error(a.output + ": exists and is not a file; not replaced");
  }
  acq::CameraSettings settings;
  settings.address = a.camera;
  const std::optional<acq::ReceivePath> path = acq::ReceivePathFromString(a.receive);
  if (!path) throw Error("--receive: unknown '" + a.receive + "' (use packet or udp)");
  settings.receive_path = *path;
  const std::optional<acq::TriggerMode> trigger = acq::TriggerModeFromString(a.trigger);
  if (!trigger) throw Error("--trigger: unknown '" + a.trigger + "' (use free, software or line)");
  settings.trigger = *trigger;
  if (a.pixel_format == "mono8") settings.pixel_format = scanner::PixelFormat::kMono8;
  else if (a.pixel_format == "mono16") settings.pixel_format = scanner::PixelFormat::kMono16;
  else if (!a.pixel_format.empty()) throw Error("--pixel-format: unknown '" + a.pixel_format + "' (use mono8 or mono16)");
  if (!a.roi.empty()) {
    if (a.roi.size() != 4) throw Error("--roi: expected x,y,width,height");
    settings.roi_x_px = a.roi[0];
    settings.roi_y_px = a.roi[1];
    settings.roi_width_px = a.roi[2];
    settings.roi_height_px = a.roi[3];
  }
  settings.packet_size_bytes = a.packet_size;
  settings.frame_rate_hz = a.fps;
  settings.exposure_us = a.exposure_us;
  settings.gain = a.gain;
  settings.buffers = a.buffers;
  settings.watchdog_s = a.watchdog_s;
  if (!(a.queue_mb > 0.0)) throw Error("--queue-mb must be > 0");
  settings.Check();

  InstallStopHandlers();
  acq::FrameSource source(settings);
  const acq::PayloadDescription& payload = source.payload();
  if (!payload.metadata_row && payload.profile) throw Error("camera " + a.camera + ": profile without metadata");
  if (a.images && payload.profile) {
    throw Error("--images: camera " + a.camera + " sends profiles (peaks found on the camera), not images");
  }
  AcquisitionContext context = MakeContext(a, payload);
  if (std::filesystem::exists(a.output)) {
    std::filesystem::remove(a.output);
    std::filesystem::remove(a.output + "-wal");
    std::filesystem::remove(a.output + "-shm");
  }
  scanner::StripeDetector detector(context.detector);
  const acq::SimulatedMirrorDriver pattern_driver(context.header.scan_pattern);
  mapping::FrameRecorder recorder(mapping::DiveLogWriter(a.output, context.header),
                                  static_cast<std::size_t>(a.queue_mb * 1e6));
  std::printf("acquire: camera %s (%s %s), %s mode, %dx%d %s payload, receive path %s\n", a.camera.c_str(),
              payload.vendor.c_str(), payload.model.c_str(), payload.profile ? "profile" : "image",
              payload.payload_width_px, payload.payload_height_px,
              payload.format == scanner::PixelFormat::kMono8 ? "Mono8" : "Mono16", acq::ToString(settings.receive_path));
  std::fflush(stdout);

  AcquireSummary summary;
  source.Start();
  if (settings.trigger == acq::TriggerMode::kSoftware) source.SoftwareTrigger();
  double last_status = 0.0;
  std::size_t gaps_reported = 0;
  while (!StopRequested()) {
    if (a.frames > 0 && summary.frames >= a.frames) break;
    if (a.seconds > 0.0 && source.ElapsedSeconds() >= a.seconds) break;
    std::optional<acq::AcquiredFrame> frame = source.Next(std::chrono::milliseconds(100));
    const double now = source.ElapsedSeconds();
    summary.source = source.statistics();
    while (gaps_reported < summary.source.gaps.size() && summary.source.gaps[gaps_reported].resumed_at_s >= 0.0) {
      const acq::CameraGap& g = summary.source.gaps[gaps_reported++];
      std::fprintf(stderr, "%sacquire: camera silent after %.2f s; reopened (%d attempts), frames again at %.2f s\n",
                   isatty(2) ? "\n" : "", g.silent_after_s, g.reopen_attempts, g.resumed_at_s);
    }
    if (now - last_status >= 1.0) {
      PrintStatus(summary, now, recorder.statistics().queued_bytes, false);
      last_status = now;
    }
    if (!frame) continue;
    if (settings.trigger == acq::TriggerMode::kSoftware) source.SoftwareTrigger();
    mapping::FrameRecord record;
    std::optional<acq::FrameMetadata> metadata;
    if (payload.profile) {
      std::optional<acq::DecodedProfile> decoded = acq::DecodeProfile(payload.profile_layout, frame->payload);
      if (!decoded) {
        ++summary.undecodable;
        continue;
      }
      metadata = decoded->metadata;
      record.peaks_px = std::move(decoded->peaks_px);
    } else {
      scanner::StripeImage image;
      if (payload.metadata_row) {
        std::optional<acq::DecodedImage> decoded = acq::DecodeImage(payload.image_layout, frame->payload);
        if (!decoded) {
          ++summary.undecodable;
          continue;
        }
        metadata = decoded->metadata;
        image = decoded->image;
      } else {
        const acq::ImageLayout& l = payload.image_layout;
        image = {frame->payload.data(), l.width_px, l.height_px, static_cast<std::ptrdiff_t>(l.row_bytes()), l.format};
      }
      const scanner::StripeDetection detection = detector.Detect(image);
      record.peaks_px.reserve(detection.peaks.size());
      for (const scanner::StripePeak& p : detection.peaks) record.peaks_px.emplace_back(p.u_px, p.v_px);
      if (a.images) {
        mapping::LogImage log_image;
        log_image.width_px = image.width_px;
        log_image.height_px = image.height_px;
        log_image.format = image.format == scanner::PixelFormat::kMono8 ? mapping::LogPixelFormat::kMono8
                                                                         : mapping::LogPixelFormat::kMono16;
        const auto* bytes = static_cast<const std::uint8_t*>(image.data);
        log_image.bytes.assign(bytes, bytes + payload.image_layout.row_bytes() * image.height_px);
        record.image = std::move(log_image);
      }
    }
    if (metadata) {
      record.time_s = metadata->timestamp_ns * 1e-9;
      record.command = metadata->mirror_command;
      record.sweep = metadata->sweep;
    } else {
      // A camera without uwscan's metadata row: the camera's clock, and the mirror driver's
      // command for this trigger (frame numbers count from the first frame of the session).
      const acq::MirrorCommand c = pattern_driver.CommandOf(static_cast<std::uint64_t>(frame->frame_number));
      record.time_s = frame->camera_timestamp_ns * 1e-9;
      record.command = c.command;
      record.sweep = c.sweep;
    }
    summary.peaks += static_cast<std::int64_t>(record.peaks_px.size());
    recorder.Push(std::move(record));
    ++summary.frames;
  }
  summary.stop_signal = g_stop_signal.load();
  summary.seconds = source.ElapsedSeconds();
  source.Stop();
  summary.source = source.statistics();
  recorder.Finish();
  summary.recorder = recorder.statistics();
  PrintStatus(summary, summary.seconds, 0, true);
  for (const acq::CameraGap& g : summary.source.gaps) {
    if (g.resumed_at_s < 0.0) {
      std::fprintf(stderr, "acquire: camera silent since %.2f s (%d reopen attempts), not back when stopped\n",
                   g.silent_after_s, g.reopen_attempts);
    }
  }
  std::printf("%s: %lld frames (%lld peaks) in %.2f s, %.1f frames/s, %.2f MB/s; lost %lld frames "
              "(%lld incomplete), %lld undecodable, %zu camera gaps%s\n",
              a.output.c_str(), static_cast<long long>(summary.recorder.frames_written),
              static_cast<long long>(summary.peaks), summary.seconds,
              summary.seconds > 0 ? summary.frames / summary.seconds : 0.0,
              summary.seconds > 0 ? summary.source.bytes / summary.seconds * 1e-6 : 0.0,
              static_cast<long long>(summary.source.lost_frames),
              static_cast<long long>(summary.source.incomplete_frames),
              static_cast<long long>(summary.undecodable), summary.source.gaps.size(),
              summary.stop_signal != 0 ? (summary.stop_signal == SIGINT ? "; stopped by SIGINT" : "; stopped by SIGTERM") : "");
  if (!a.json.empty()) {
    nlohmann::json gaps = nlohmann::json::array();
    for (const acq::CameraGap& g : summary.source.gaps) {
      gaps.push_back({{"silent_after_s", g.silent_after_s}, {"resumed_at_s", g.resumed_at_s},
                      {"reopen_attempts", g.reopen_attempts}});
    }
    WriteJsonFile(a.json, {{"frames", summary.recorder.frames_written},
                           {"peaks", summary.peaks},
                           {"seconds", summary.seconds},
                           {"frames_per_s", summary.seconds > 0 ? summary.frames / summary.seconds : 0.0},
                           {"mb_per_s", summary.seconds > 0 ? summary.source.bytes / summary.seconds * 1e-6 : 0.0},
                           {"lost_frames", summary.source.lost_frames},
                           {"incomplete_frames", summary.source.incomplete_frames},
                           {"stale_frames", summary.source.stale_frames},
                           {"undecodable_frames", summary.undecodable},
                           {"aravis_missing_frames", summary.source.aravis_missing_frames},
                           {"aravis_underruns", summary.source.aravis_underruns},
                           {"max_queued_mb", summary.recorder.max_queued_bytes * 1e-6},
                           {"recorder_blocked_s", summary.recorder.blocked_s},
                           {"gaps", gaps},
                           {"stopped_by_signal", summary.stop_signal != 0}});
  }
}

}  // namespace

void AddFakeCameraCommand(CLI::App& app) {
  auto args = std::make_shared<FakeCameraArgs>();
  CLI::App* cmd = app.add_subcommand(
      "fake-camera", "serve a scene's simulated frames as a GigE Vision camera (Aravis's fake camera) until stopped");
  cmd->add_option("scene", args->scene, "scene YAML (data/scenes/*.yaml)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--address", args->address, "interface address (or name) to answer on")->capture_default_str();
  cmd->add_option("--mode", args->mode, "profile (peaks found on the camera) or image (rendered frames)")
      ->capture_default_str();
  cmd->add_option("--fps", args->fps, "frames per second (default: the scan pattern's rate; at most 1000)");
  cmd->add_option("--loss", args->loss, "fraction of frames withheld whole, drawn per frame from --seed")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the frame losses")->capture_default_str();
  cmd->add_option("--peak-rows", args->peak_rows, "profile mode: peaks carried per image line")->capture_default_str();
  cmd->add_option("--seconds", args->seconds, "stop after this long (default: until SIGINT or SIGTERM)");
  cmd->callback([args] { RunFakeCamera(*args); });
}

void AddAcquireCommand(CLI::App& app) {
  auto args = std::make_shared<AcquireArgs>();
  CLI::App* cmd = app.add_subcommand("acquire", "record a GigE Vision camera's frames into a new dive log");
  cmd->add_option("--camera", args->camera, "camera IPv4 address (opened directly, never discovered)")->required();
  cmd->add_option("-o,--output", args->output, "dive log to create (.db)")->required();
  cmd->add_option("--frames", args->frames, "stop after this many frames")->check(CLI::PositiveNumber);
  cmd->add_option("--seconds", args->seconds, "stop after this long")->check(CLI::PositiveNumber);
  cmd->add_flag("--images", args->images, "image mode: store the images as well as the detected peaks");
  cmd->add_option("--scene", args->scene, "simulated camera: the scene it serves (scanner and scan pattern)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--scanner", args->scanner_file, "real camera: the scanner (calibration) file")
      ->check(CLI::ExistingFile);
  cmd->add_option("--receive", args->receive, "Aravis's receive path: packet (raw packet socket) or udp")
      ->capture_default_str();
  cmd->add_option("--trigger", args->trigger, "free, software or line (Line0)")->capture_default_str();
  cmd->add_option("--pixel-format", args->pixel_format, "mono8 or mono16 (default: the camera's)");
  cmd->add_option("--packet-size", args->packet_size, "GigE Vision packet size, bytes (default: the camera's)");
  cmd->add_option("--fps", args->fps, "frame rate in free run (default: the camera's)");
  cmd->add_option("--exposure-us", args->exposure_us, "exposure time, microseconds (default: the camera's)");
  cmd->add_option("--gain", args->gain, "gain, camera units (default: the camera's)");
  cmd->add_option("--roi", args->roi, "region of interest x,y,width,height (pixels)")->delimiter(',');
  cmd->add_option("--buffers", args->buffers, "Aravis buffers (frames the driver holds)")->capture_default_str();
  cmd->add_option("--queue-mb", args->queue_mb,
                  "frames waiting for the disk before the reader waits, MB (then the buffers fill and "
                  "the camera's frames are lost and counted)")
      ->capture_default_str();
  cmd->add_option("--watchdog-s", args->watchdog_s, "reopen a camera silent this long, seconds")->capture_default_str();
  cmd->add_option("--json", args->json, "also write the figures as JSON");
  cmd->add_flag("--force", args->force, "replace an existing log at the output path");
  cmd->callback([args] { RunAcquire(*args); });
}

}  // namespace uwscan::app
