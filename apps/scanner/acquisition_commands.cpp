#include "apps/scanner/acquisition_commands.hpp"

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

#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/progress_bar.hpp"
#include "apps/cli/stop_signal.hpp"
#include "apps/scanner/camera_frames.hpp"
#include "mapping/inspection/frame_recorder.hpp"
#include "mapping/log/dive_log.hpp"
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
  if (a.mode == "image")
    options.mode = acq::FakeCameraMode::kImage;
  else if (a.mode == "profile")
    options.mode = acq::FakeCameraMode::kProfile;
  else
    throw Error("--mode: unknown '" + a.mode + "' (use image or profile)");
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
    camera = std::make_unique<acq::FakeCamera>(
        simulator, options, [&bar](double f) { bar.Update("prepare frames", f); });
  }
  std::printf(
      "fake-camera: serving %lld frames of %s (%s scanner, %s mode, %zu-byte payload) at %.1f "
      "frames/s on %s"
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
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >=
            a.seconds) {
      break;
    }
  }
  const acq::FakeCameraStatistics s = camera->statistics();
  camera.reset();
  std::printf(
      "fake-camera: stopped; %llu frames sent, %llu withheld (loss), %llu peaks beyond %d per "
      "line\n",
      static_cast<unsigned long long>(s.frames_sent),
      static_cast<unsigned long long>(s.frames_dropped),
      static_cast<unsigned long long>(s.peaks_dropped), a.peak_rows);
}

// --------------------------------------------------------------------------------------------
struct AcquireArgs {
  CameraArgs camera;
  std::string output;
  std::int64_t frames = 0;
  double seconds = 0.0;
  bool images = false;
  bool force = false;
  double queue_mb = 512.0;
  std::string json;
};

void PrintStatus(const ReadSummary& s, double seconds, std::size_t queued_bytes, bool final_line) {
  const double fps = seconds > 0 ? s.frames / seconds : 0.0;
  const double mbps = seconds > 0 ? s.source.bytes / seconds * 1e-6 : 0.0;
  std::fprintf(stderr,
               "%sacquire: %lld frames, %.1f frames/s, %.2f MB/s, %lld lost, queue %.1f MB%s",
               isatty(2) ? "\r" : "", static_cast<long long>(s.frames), fps, mbps,
               static_cast<long long>(s.source.lost_frames), queued_bytes * 1e-6,
               final_line || !isatty(2) ? "\n" : "   ");
}

void RunAcquire(const AcquireArgs& a) {
  if (a.frames > 0 && a.seconds > 0.0) throw Error("--frames and --seconds: give one of them");
  CheckNewLogPath(a.output, a.force, "-o");
  if (!(a.queue_mb > 0.0)) throw Error("--queue-mb must be > 0");
  const acq::CameraSettings settings = MakeCameraSettings(a.camera);

  InstallStopHandlers();
  acq::FrameSource source(settings);
  const acq::PayloadDescription& payload = source.payload();
  const AcquisitionContext context = MakeContext(a.camera, payload, "acquire");
  CameraFrameDecoder decoder(payload, context, a.images);
  RemoveLog(a.output);
  mapping::FrameRecorder recorder(mapping::DiveLogWriter(a.output, context.header),
                                  static_cast<std::size_t>(a.queue_mb * 1e6));
  std::printf("acquire: camera %s (%s %s), %s mode, %dx%d %s payload, receive path %s\n",
              a.camera.camera.c_str(), payload.vendor.c_str(), payload.model.c_str(),
              payload.profile ? "profile" : "image", payload.payload_width_px,
              payload.payload_height_px,
              payload.format == scanner::PixelFormat::kMono8 ? "Mono8" : "Mono16",
              acq::ToString(settings.receive_path));
  std::fflush(stdout);

  const ReadSummary summary = ReadFrames(
      source, decoder, ReadLimits{a.frames, a.seconds}, "acquire",
      [&recorder](mapping::FrameRecord&& record, const acq::AcquiredFrame&) {
        recorder.Push(std::move(record));
      },
      [&recorder](const ReadSummary& s, double now) {
        PrintStatus(s, now, recorder.statistics().queued_bytes, false);
      });
  recorder.Finish();
  const mapping::FrameRecorderStatistics recorded = recorder.statistics();
  PrintStatus(summary, summary.seconds, 0, true);
  std::printf(
      "%s: %lld frames (%lld peaks) in %.2f s, %.1f frames/s, %.2f MB/s; lost %lld frames "
      "(%lld incomplete), %lld undecodable, %zu camera gaps%s\n",
      a.output.c_str(), static_cast<long long>(recorded.frames_written),
      static_cast<long long>(summary.peaks), summary.seconds,
      summary.seconds > 0 ? summary.frames / summary.seconds : 0.0,
      summary.seconds > 0 ? summary.source.bytes / summary.seconds * 1e-6 : 0.0,
      static_cast<long long>(summary.source.lost_frames),
      static_cast<long long>(summary.source.incomplete_frames),
      static_cast<long long>(summary.undecodable), summary.source.gaps.size(),
      summary.stop_signal != 0
          ? (summary.stop_signal == SIGINT ? "; stopped by SIGINT" : "; stopped by SIGTERM")
          : "");
  if (!a.json.empty()) {
    nlohmann::json gaps = nlohmann::json::array();
    for (const acq::CameraGap& g : summary.source.gaps) {
      gaps.push_back({{"silent_after_s", g.silent_after_s},
                      {"resumed_at_s", g.resumed_at_s},
                      {"reopen_attempts", g.reopen_attempts}});
    }
    WriteJsonFile(
        a.json,
        {{"frames", recorded.frames_written},
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
         {"max_queued_mb", recorded.max_queued_bytes * 1e-6},
         {"recorder_blocked_s", recorded.blocked_s},
         {"gaps", gaps},
         {"stopped_by_signal", summary.stop_signal != 0}});
  }
}

}  // namespace

void AddFakeCameraCommand(CLI::App& app) {
  auto args = std::make_shared<FakeCameraArgs>();
  CLI::App* cmd = app.add_subcommand("fake-camera",
                                     "serve a scene's simulated frames as a GigE Vision camera "
                                     "(Aravis's fake camera) until stopped");
  cmd->add_option("scene", args->scene, "scene YAML (data/scenes/*.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--address", args->address, "interface address (or name) to answer on")
      ->capture_default_str();
  cmd->add_option("--mode", args->mode,
                  "profile (peaks found on the camera) or image (rendered frames)")
      ->capture_default_str();
  cmd->add_option("--fps", args->fps,
                  "frames per second (default: the scan pattern's rate; at most 1000)");
  cmd->add_option("--loss", args->loss,
                  "fraction of frames withheld whole, drawn per frame from --seed")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the frame losses")->capture_default_str();
  cmd->add_option("--peak-rows", args->peak_rows, "profile mode: peaks carried per image line")
      ->capture_default_str();
  cmd->add_option("--seconds", args->seconds,
                  "stop after this long (default: until SIGINT or SIGTERM)");
  cmd->callback([args] { RunFakeCamera(*args); });
}

void AddAcquireCommand(CLI::App& app) {
  auto args = std::make_shared<AcquireArgs>();
  CLI::App* cmd =
      app.add_subcommand("acquire", "record a GigE Vision camera's frames into a new dive log");
  AddCameraOptions(*cmd, args->camera);
  cmd->add_option("-o,--output", args->output, "dive log to create (.db)")->required();
  cmd->add_option("--frames", args->frames, "stop after this many frames")->check(kPositiveNumber);
  cmd->add_option("--seconds", args->seconds, "stop after this long")->check(kPositiveNumber);
  cmd->add_flag("--images", args->images,
                "image mode: store the images as well as the detected peaks");
  cmd->add_option(
         "--queue-mb", args->queue_mb,
         "frames waiting for the disk before the reader waits, MB (then the buffers fill and "
         "the camera's frames are lost and counted)")
      ->capture_default_str();
  cmd->add_option("--json", args->json, "also write the figures as JSON");
  cmd->add_flag("--force", args->force, "replace an existing log at the output path");
  cmd->callback([args] { RunAcquire(*args); });
}

}  // namespace uwscan::app
