#include "apps/mapping/inspect_command.hpp"

#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/malloc_arena.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/reference_options.hpp"
#include "apps/cli/stop_signal.hpp"
#include "apps/scanner/camera_frames.hpp"
#include "mapping/inspection/live_inspection.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/temporary_folder.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/live_view.hpp"

namespace uwscan::app {
namespace {

namespace acq = scanner::acquisition;

struct InspectArgs {
  CameraArgs camera;
  std::string log;
  std::string map;
  std::string json;
  std::int64_t frames = 0;
  double seconds = 0.0;
  bool images = false;
  bool ascii = false;
  bool force = false;
  bool view = false;
  std::string screenshot;
  double queue_mb = 512.0;
  int live_queue = 4;
  double voxel_m = 0.005;
  int sweeps_per_submap = mapping::MapperOptions{}.sweeps_per_submap;
  int threads = 0;
  LiveReferenceArgs reference;  // the live map coloured by its deviation from it
};

// The reference the live map is coloured against (--reference), read before the camera opens.
std::unique_ptr<mapping::LiveDeviation> LoadReference(const InspectArgs& a, bool view) {
  if (!a.reference.path.empty() && !view)
    throw Error("--reference: colours the live view; give --view or --screenshot");
  return LoadLiveReference(a.reference);
}

void PrintStatus(const ReadSummary& r, const mapping::InspectionStatistics& s, double seconds,
                 bool final_line) {
  std::fprintf(stderr,
               "%sinspect: %lld frames, %.1f frames/s, %lld lost; mapped %lld, skipped %lld; "
               "latency to map %.1f ms; "
               "log queue %.1f MB%s",
               isatty(2) ? "\r" : "", static_cast<long long>(r.frames),
               seconds > 0 ? r.frames / seconds : 0.0, static_cast<long long>(r.source.lost_frames),
               static_cast<long long>(s.frames_mapped), static_cast<long long>(s.frames_skipped),
               s.receive_to_map.median_s * 1e3, s.log.queued_bytes * 1e-6,
               final_line || !isatty(2) ? "\n" : "   ");
}

nlohmann::json LatencyJson(const mapping::LatencyFigures& f) {
  return {{"frames", f.frames}, {"median_s", f.median_s}, {"p95_s", f.p95_s}, {"max_s", f.max_s}};
}

void WriteReport(const InspectArgs& a, const ReadSummary& r,
                 const mapping::InspectionResult& result) {
  const mapping::InspectionStatistics& s = result.statistics;
  nlohmann::json gaps = nlohmann::json::array();
  for (const acq::CameraGap& g : r.source.gaps) {
    gaps.push_back({{"silent_after_s", g.silent_after_s},
                    {"resumed_at_s", g.resumed_at_s},
                    {"reopen_attempts", g.reopen_attempts}});
  }
  nlohmann::json latency = {{"receive_to_map", LatencyJson(s.receive_to_map)}};
  if (s.capture_to_map.frames > 0) latency["capture_to_map"] = LatencyJson(s.capture_to_map);
  WriteJsonFile(a.json, {{"frames_received", s.frames_received},
                         {"frames_logged", s.frames_logged},
                         {"frames_mapped", s.frames_mapped},
                         {"frames_skipped", s.frames_skipped},
                         {"frames_without_navigation", s.frames_without_navigation},
                         {"frames_out_of_order", s.frames_out_of_order},
                         {"clock_restarts", s.clock_restarts},
                         {"lost_frames", r.source.lost_frames},
                         {"incomplete_frames", r.source.incomplete_frames},
                         {"undecodable_frames", r.undecodable},
                         {"seconds", r.seconds},
                         {"frames_per_s", r.seconds > 0 ? r.frames / r.seconds : 0.0},
                         {"mb_per_s", r.seconds > 0 ? r.source.bytes / r.seconds * 1e-6 : 0.0},
                         {"points_mapped", s.points_mapped},
                         {"map_points", result.map.size()},
                         {"submaps", s.submaps},
                         {"latency_s", latency},
                         {"navigation", "fixed scanner: vehicle at the origin"},
                         {"log", a.log},
                         {"gaps", gaps},
                         {"stopped_by_signal", r.stop_signal != 0}});
}

// Every argument checked before the camera is opened.
void CheckInspectArgs(const InspectArgs& a) {
  if (a.frames > 0 && a.seconds > 0.0) throw Error("--frames and --seconds: give one of them");
  if (!a.log.empty()) CheckNewLogPath(a.log, a.force, "--log");
  for (const auto& [path, option] :
       {std::pair{a.map, "-o"}, {a.json, "--json"}, {a.screenshot, "--screenshot"}}) {
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    if (!path.empty() && !parent.empty() && !std::filesystem::is_directory(parent)) {
      throw Error(std::string(option) + " " + path + ": folder '" + parent.string() +
                  "' does not exist");
    }
  }
  if (!a.map.empty()) CheckCloudOutputPath(a.map, "-o");
  if (!(a.queue_mb > 0.0)) throw Error("--queue-mb must be > 0");
  if (!a.screenshot.empty() && a.frames <= 0 && a.seconds <= 0.0) {
    throw Error("--screenshot: say when to take the picture with --frames N (or --seconds S)");
  }
}

mapping::InspectionOptions InspectionOptionsOf(const InspectArgs& a) {
  mapping::InspectionOptions options;
  options.log_queue_bytes = static_cast<std::size_t>(a.queue_mb * 1e6);
  options.live_queue_frames = a.live_queue;
  options.map_voxel_m = a.voxel_m;
  options.mapper.sweeps_per_submap = a.sweeps_per_submap;
  options.mapper.threads = a.threads;
  options.mapper.spill_folder = TemporaryFolder();
  options.table_cache = TableCache();
  options.Check();
  return options;
}

std::unique_ptr<viewer::LiveView> MakeLiveView(const InspectArgs& a, bool deviations) {
  viewer::LiveViewOptions live;
  live.offscreen = !a.screenshot.empty();
  if (deviations) live.render.colour = viewer::ColourMode::kDeviation;
  auto live_view = std::make_unique<viewer::LiveView>(live);
  if (!a.screenshot.empty()) live_view->SetFinalScreenshot(a.screenshot);
  return live_view;
}

// Runs `read` on its own thread while the view owns this one (VTK's GUI thread), or on this one
// without a view; returns what the reader failed with, else what the view failed with.
std::exception_ptr ReadBesideView(viewer::LiveView* view, const std::string& title,
                                  const std::function<std::exception_ptr()>& read) {
  if (view == nullptr) return read();
  std::exception_ptr read_failure, view_failure;
  std::thread reader([&] { read_failure = read(); });
  try {
    view->Run(title);
  } catch (...) {
    view_failure = std::current_exception();
  }
  RequestStop();  // the window was closed (or the reader ended)
  reader.join();
  return read_failure ? read_failure : view_failure;
}

void PrintInspectSummary(const InspectArgs& a, const ReadSummary& read,
                         const mapping::InspectionResult& result) {
  const mapping::InspectionStatistics& s = result.statistics;
  std::printf(
      "inspect: %lld frames received in %.2f s (%.1f frames/s), %lld lost, %lld undecodable; "
      "logged %lld; "
      "mapped %lld, skipped %lld (live queue %d)\n",
      static_cast<long long>(s.frames_received), read.seconds,
      read.seconds > 0 ? read.frames / read.seconds : 0.0,
      static_cast<long long>(read.source.lost_frames), static_cast<long long>(read.undecodable),
      static_cast<long long>(s.frames_logged), static_cast<long long>(s.frames_mapped),
      static_cast<long long>(s.frames_skipped), a.live_queue);
  if (s.frames_without_navigation > 0) {
    std::printf("inspect: %lld frames logged but not mapped: no navigation around their time\n",
                static_cast<long long>(s.frames_without_navigation));
  }
  std::printf("inspect: latency to the map, receive -> map median %.2f ms (p95 %.2f, max %.2f)",
              s.receive_to_map.median_s * 1e3, s.receive_to_map.p95_s * 1e3,
              s.receive_to_map.max_s * 1e3);
  if (s.capture_to_map.frames > 0) {
    std::printf(", capture -> map median %.2f ms (p95 %.2f, max %.2f)",
                s.capture_to_map.median_s * 1e3, s.capture_to_map.p95_s * 1e3,
                s.capture_to_map.max_s * 1e3);
  } else {
    std::printf("; capture -> map unknown (the camera's clock is not the host's)");
  }
  std::printf("\ninspect: map %zu points (%lld points placed) in %d submaps%s%s%s\n",
              result.map.size(), static_cast<long long>(s.points_mapped), s.submaps,
              a.map.empty() ? "" : ", written to ", a.map.c_str(),
              read.stop_signal != 0
                  ? (read.stop_signal == SIGINT ? "; stopped by SIGINT" : "; stopped by SIGTERM")
                  : "");
}

void RunInspect(const InspectArgs& a) {
  CheckInspectArgs(a);
  const mapping::InspectionOptions options = InspectionOptionsOf(a);
  // Before the reference's normals or the camera start any thread.
  if (options.mapper.whole_solve_lag_s > 0.0) UseOneMallocArena();
  const bool view = a.view || !a.screenshot.empty();
  if (view) viewer::RequireDisplay();  // before the camera, not after the dive
  const std::unique_ptr<mapping::LiveDeviation> reference = LoadReference(a, view);
  const acq::CameraSettings settings = MakeCameraSettings(a.camera);

  InstallStopHandlers();
  acq::FrameSource source(settings);
  const acq::PayloadDescription& payload = source.payload();
  const AcquisitionContext context = MakeContext(a.camera, payload, "inspect");
  CameraFrameDecoder decoder(payload, context, a.images);
  const std::unique_ptr<viewer::LiveView> live_view =
      view ? MakeLiveView(a, reference != nullptr) : nullptr;
  if (!a.log.empty()) RemoveLog(a.log);
  // No navigation from a camera alone: the scanner is held fixed, the vehicle at the origin.
  mapping::LiveInspection inspection(context.header, a.log, context.T_V_C,
                                     mapping::NavigationNoise{}, options,
                                     [&live_view, &reference](const mapping::MappedFrame& f) {
                                       if (!live_view) return;
                                       viewer::LiveCloud cloud;
                                       cloud.time_s = f.time_s;
                                       cloud.points_W.assign(f.points_W.begin(), f.points_W.end());
                                       if (reference)
                                         cloud.deviation_m = reference->Deviations(cloud.points_W);
                                       live_view->Push(std::move(cloud));
                                     });
  std::printf(
      "inspect: camera %s (%s %s), %s mode, %dx%d payload; scanner fixed (no navigation), map in "
      "the "
      "vehicle frame; %s\n",
      a.camera.camera.c_str(), payload.vendor.c_str(), payload.model.c_str(),
      payload.profile ? "profile" : "image", payload.payload_width_px, payload.payload_height_px,
      a.log.empty() ? "no log" : ("logging to " + a.log).c_str());
  std::fflush(stdout);

  ReadSummary read;
  mapping::InspectionResult result;
  auto acquire = [&]() -> std::exception_ptr {
    std::exception_ptr failure;
    try {
      read = ReadFrames(
          source, decoder, ReadLimits{a.frames, a.seconds}, "inspect",
          [&inspection](mapping::FrameRecord&& record, const acq::AcquiredFrame& frame) {
            inspection.Push(ToInspectionFrame(std::move(record), frame));
          },
          [&inspection](const ReadSummary& r, double now) {
            PrintStatus(r, inspection.statistics(), now, false);
          });
      result = inspection.Finish();
    } catch (...) {
      failure = std::current_exception();
    }
    if (live_view) live_view->RequestStop();
    return failure;
  };
  if (const std::exception_ptr failure =
          ReadBesideView(live_view.get(), "uwscan inspect " + a.camera.camera, acquire)) {
    std::rethrow_exception(failure);
  }
  PrintStatus(read, result.statistics, read.seconds, true);
  if (!a.map.empty()) perception::WriteCloud(a.map, result.map, !a.ascii);
  PrintInspectSummary(a, read, result);
  if (!a.screenshot.empty()) std::printf("%s: written\n", a.screenshot.c_str());
  if (!a.json.empty()) WriteReport(a, read, result);
}

}  // namespace

void AddInspectCommand(CLI::App& app) {
  auto a = std::make_shared<InspectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "inspect",
      "online inspection: a camera's frames logged (never dropped), stripe peaks triangulated and "
      "mapped live "
      "(the newest frames the mapper keeps up with; skipped ones counted), shown with --view");
  cmd->footer(
      "Navigation: a camera alone gives none, so the scanner is taken as fixed: the vehicle is "
      "held at the origin\n"
      "(T_W_V = identity at every frame) and the map is in the vehicle frame (the camera frame "
      "moved by the\n"
      "scene's camera mount; identity for a real camera). Sweeps of a static scene land on each "
      "other; a moving\n"
      "vehicle is mapped afterwards with `uwscan map` on a log that has its navigation.\n"
      "Latency is measured to the moment a frame's points are placed in the map: from the host "
      "receiving the\n"
      "frame, and from the camera's exposure when the camera's clock is the host's (PTP, the fake "
      "camera).");
  AddCameraOptions(*cmd, a->camera);
  cmd->add_option("--log", a->log,
                  "dive log to create (.db): every frame received, each committed");
  cmd->add_option("-o,--map", a->map, "map to write at the end (.ply or .pcd), voxelised");
  cmd->add_flag("--ascii", a->ascii, "write the map as ASCII instead of binary");
  cmd->add_option("--json", a->json,
                  "figures as JSON: frames received, logged, mapped, skipped, latency");
  cmd->add_option("--frames", a->frames, "stop after this many frames")->check(kPositiveNumber);
  cmd->add_option("--seconds", a->seconds, "stop after this long")->check(kPositiveNumber);
  cmd->add_flag("--images", a->images, "image mode: log the images as well as the detected peaks");
  cmd->add_flag("--view", a->view, "show the map live (needs an X display)");
  cmd->add_option("--screenshot", a->screenshot,
                  "render the live view offscreen and write its last picture to this PNG (with "
                  "--frames or --seconds)");
  cmd->add_option("--queue-mb", a->queue_mb,
                  "frames waiting for the disk before the reader waits, MB (then the camera's "
                  "buffers fill and its "
                  "frames are lost and counted)")
      ->capture_default_str();
  cmd->add_option("--live-queue", a->live_queue,
                  "frames waiting for the mapper; a newer frame skips the oldest")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--voxel", a->voxel_m, "map voxel, metres")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--sweeps-per-submap", a->sweeps_per_submap, "sweeps grouped into one submap")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--threads", a->threads, "threads of the mapper's ICP and normals (0: all cores)")
      ->check(kNonNegativeNumber);
  cmd->add_flag("--force", a->force, "replace an existing log at the --log path");
  AddLiveReferenceOptions(*cmd, a->reference,
                          "the live map coloured by its deviation from it (with --view or "
                          "--screenshot)");
  cmd->callback([a] { RunInspect(*a); });
}

}  // namespace uwscan::app
