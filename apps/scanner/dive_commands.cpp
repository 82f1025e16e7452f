#include "apps/scanner/dive_commands.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/progress_bar.hpp"
#include "apps/cli/text_file.hpp"
#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "mapping/reconstruction/reconstruction.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "scanner/calibration/calibration_scene.hpp"
#include "scanner/calibration/dataset_simulation.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/scene_mesh.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::app {
namespace {

struct SimulateArgs {
  std::string scene;
  std::string output;
  std::string design;
  bool images = false;
  bool force = false;
  int threads = 0;
};

// A calibration scene (a `calibration:` section) simulates a dataset folder, not a dive.
bool IsCalibrationScene(const std::string& text) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("calibration:", 0) == 0) return true;
  }
  return false;
}

void RunSimulateCalibration(const SimulateArgs& a) {
  if (a.images) throw Error("--images: a calibration dataset is made of images already");
  // A dataset is a folder: an existing one is checked below; a new one needs a writable parent.
  if (!std::filesystem::exists(a.output)) CheckOutputPath(a.output, "-o", {a.scene});
  if (std::filesystem::exists(a.output)) {
    if (!a.force)
      throw Error(a.output + ": exists (a dataset folder is never overwritten; use --force)");
    // --force replaces a dataset, never an arbitrary folder.
    if (!std::filesystem::is_regular_file(std::filesystem::path(a.output) / "manifest.yaml")) {
      throw Error(a.output +
                  ": exists and is not a calibration dataset (no manifest.yaml); not replaced");
    }
    scanner::calibration::LoadCalibrationScene(
        a.scene);  // a bad scene fails before anything is removed
    std::filesystem::remove_all(a.output);
  }
  {
    ProgressBar bar;
    scanner::calibration::SimulateCalibrationDataset(
        a.scene, a.output, [&bar](double f) { bar.Update("simulate", f); });
  }
  std::printf("%s: calibration dataset written (manifest.yaml, images, truth.yaml)\n",
              a.output.c_str());
}

// A dive log holds about 7 kB a frame with exact peaks (the 30-minute dive's 610,000 frames take
// 4.5 GB) and more with images: a kilobyte a frame is a floor no dive goes under.
constexpr double kMinLogBytesPerFrame = 1000.0;

// Refuses, before any simulation, a dive that the output's disk cannot hold even at that floor (a
// scene asking for millions of sweeps filled memory and disk hours later).
void RequireRoomForDive(std::int64_t frames, const std::filesystem::path& output) {
  std::error_code ec;
  const std::filesystem::path folder = output.has_parent_path() ? output.parent_path() : ".";
  const std::filesystem::space_info space = std::filesystem::space(folder, ec);
  const double needed = kMinLogBytesPerFrame * static_cast<double>(frames);
  if (ec || needed <= static_cast<double>(space.available)) return;  // no answer: the write says
  char text[160];
  std::snprintf(text, sizeof(text),
                ": the scene's %lld frames need at least %.3g GB, more than "
                "the %.3g GB free there",
                static_cast<long long>(frames), needed * 1e-9,
                static_cast<double>(space.available) * 1e-9);
  throw Error(output.string() + text);
}

void RunSimulate(const SimulateArgs& a) {
  if (IsCalibrationScene(ReadText(a.scene))) {
    if (!a.design.empty()) throw Error("--design: a calibration scene has no structure to model");
    return RunSimulateCalibration(a);
  }
  CheckOutputPath(a.output, "-o", {a.scene});
  if (!a.design.empty()) CheckOutputPath(a.design, "--design", {a.scene, a.output});
  if (std::filesystem::exists(a.output) && !a.force) {
    throw Error(a.output + ": exists (a dive log is never overwritten; use --force)");
  }
  // Everything is checked before --force removes the old log.
  const scanner::sim::Scene scene = scanner::sim::LoadScene(a.scene);
  const scanner::sim::Simulator simulator(scene);
  RequireRoomForDive(simulator.frame_count(), a.output);
  if (a.images && !scene.effects.AnyImageStage()) {
    throw Error("--images: scene " + a.scene +
                " renders no frames (no image effect is on); its dive holds exact peaks");
  }
  if (std::filesystem::exists(a.output) && !std::filesystem::is_regular_file(a.output)) {
    throw Error(a.output + ": exists and is not a file; not replaced");
  }
  mapping::DiveSimulationOptions options;
  options.store_images = a.images;
  options.threads = a.threads;
  options.producer = std::string("uwscan simulate ") + UWSCAN_VERSION;
  // The dive is written under a temporary name and replaces the output (an older log under
  // --force) only when complete: killed or failing, the output is the old file or none.
  mapping::DiveSimulationSummary summary;
  mapping::WriteDiveLogAtomically(a.output, [&](const std::filesystem::path& partial) {
    ProgressBar bar;
    summary = mapping::SimulateDive(simulator, ReadText(a.scene), partial, options,
                                    [&bar](double f) { bar.Update("simulate", f); });
  });
  std::printf("%s: %lld frames (%s scanner, %s), %lld peaks, %lld navigation records%s, %.2f s\n",
              a.output.c_str(), static_cast<long long>(summary.frames),
              scanner::ToString(scene.scanner.model.kind()),
              scene.effects.AnyImageStage() ? "rendered frames, detected stripes" : "exact peaks",
              static_cast<long long>(summary.peaks),
              static_cast<long long>(summary.navigation_records),
              summary.images_stored ? ", images stored" : "", summary.seconds);
  if (!a.design.empty()) {
    const scanner::TriangleMesh design = scanner::sim::SceneMesh(scene);
    scanner::WriteMeshPly(design, a.design);
    std::printf("%s: the scene's %zu objects as built, %zu triangles (world frame, metres)\n",
                a.design.c_str(), scene.objects.size(), design.triangles.size());
  }
}

struct ReconstructArgs {
  std::string log;
  std::string output;
  std::string method;
  std::string json;
  std::string calibration;
  bool ascii = false;
  bool scanner_frame = false;
  bool no_table_cache = false;
};

void RunReconstruct(const ReconstructArgs& a) {
  CheckCloudOutputPath(a.output, "-o", {a.log, a.calibration});
  if (!a.json.empty()) CheckOutputPath(a.json, "--json", {a.log, a.calibration, a.output});
  mapping::ReconstructionOptions options;
  if (!a.method.empty()) {
    options.method = scanner::ParseTriangulationMethod(a.method);
    if (!options.method)
      throw Error("--method: unknown '" + a.method + "' (use plane, cone or ray)");
  }
  options.use_navigation = !a.scanner_frame;
  if (!a.no_table_cache) options.table_cache = TableCache();
  if (!a.calibration.empty()) {
    options.calibration = scanner::LoadScanner(a.calibration);
  }
  const mapping::DiveLogReader log(a.log);
  mapping::Reconstruction r;
  {
    ProgressBar bar;
    r = mapping::Reconstruct(log, options, [&bar](double f) { bar.Update("reconstruct", f); });
  }
  if (r.points.empty()) throw Error(a.log + ": no frame gave a point; nothing to write");
  perception::WriteCloud(a.output, perception::MakeCloud(r.points), !a.ascii);
  const double rate =
      r.triangulation_seconds > 0.0 ? r.points.size() / r.triangulation_seconds : 0.0;
  std::printf("%s: %zu points from %lld frames (%lld peaks), %s, %s frame\n", a.output.c_str(),
              r.points.size(), static_cast<long long>(r.frames), static_cast<long long>(r.peaks),
              scanner::ToString(r.method), r.world_frame ? "world" : "scanner");
  std::printf("tables %.3f s, triangulation %.4f s (%.2f M points/s)\n", r.table_seconds,
              r.triangulation_seconds, rate * 1e-6);
  nlohmann::json json = {{"points", r.points.size()},
                         {"frames", r.frames},
                         {"peaks", r.peaks},
                         {"method", scanner::ToString(r.method)},
                         {"world_frame", r.world_frame},
                         {"table_seconds", r.table_seconds},
                         {"triangulation_seconds", r.triangulation_seconds}};
  if (const std::optional<mapping::TruthError> e = mapping::CompareToTruth(r)) {
    std::printf(
        "error against ground truth (%lld points): mean %.4g mm, std %.4g mm, rms %.4g mm, max "
        "%.4g mm\n",
        static_cast<long long>(e->points), e->mean_m * 1e3, e->std_m * 1e3, e->rms_m * 1e3,
        e->max_m * 1e3);
    json["truth_error"] = {{"points", e->points},
                           {"mean_m", e->mean_m},
                           {"std_m", e->std_m},
                           {"rms_m", e->rms_m},
                           {"max_m", e->max_m}};
  }
  if (!a.json.empty()) WriteJsonFile(a.json, json);
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand("simulate",
                                     "simulate a scene into a new dive log (SQLite), or a "
                                     "calibration scene into a dataset folder");
  cmd->add_option("scene", args->scene, "scene YAML (data/scenes/*.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "dive log to create (.db)")->required();
  cmd->add_flag("--images", args->images,
                "store the rendered frames in the log (image effects on)");
  cmd->add_flag("--force", args->force, "replace an existing log at the output path");
  cmd->add_option("--design", args->design,
                  "also write the scene's objects as one mesh in the world frame (.ply): the "
                  "structure as built, a reference for `uwscan compare`");
  cmd->add_option("--threads", args->threads, "frames simulated in parallel (0: all cores)")
      ->check(kNonNegativeNumber);
  cmd->callback([args] { RunSimulate(*args); });
}

void AddReconstructCommand(CLI::App& app) {
  auto args = std::make_shared<ReconstructArgs>();
  CLI::App* cmd = app.add_subcommand("reconstruct", "triangulate a dive log into a point cloud");
  cmd->add_option("log", args->log, "dive log (.db)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "point cloud to write (.ply or .pcd)")->required();
  cmd->add_option("--method", args->method,
                  "plane, cone or ray (default: cone for the galvanometer, plane for MEMS)");
  cmd->add_option("--json", args->json, "also write the figures as JSON");
  cmd->add_option(
         "--calibration", args->calibration,
         "calibration file (from `calibrate`) to triangulate with instead of the log's scanner")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--ascii", args->ascii, "write an ASCII cloud instead of binary");
  cmd->add_flag("--scanner-frame", args->scanner_frame,
                "keep points in the camera frame even when the log has navigation");
  cmd->add_flag(
      "--no-table-cache", args->no_table_cache,
      "fit the cone table again instead of reusing the one kept for this calibration "
      "($UWSCAN_TABLE_CACHE, else $XDG_CACHE_HOME/uwscan/tables, else ~/.cache/uwscan/tables)");
  cmd->callback([args] { RunReconstruct(*args); });
}

}  // namespace uwscan::app
