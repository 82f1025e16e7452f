#include "apps/scanner/demo_command.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/data_folder.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/progress_bar.hpp"
#include "apps/cli/text_file.hpp"
#include "bench/scratch_folder.hpp"
#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "mapping/reconstruction/reconstruction.hpp"
#include "scanner/common/error.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/screenshot.hpp"
#include "viewer/scene/scene_files.hpp"

namespace uwscan::app {
namespace {

struct DemoArgs {
  std::string scene;  // empty: the default scene (DefaultScene)
  int threads = 0;
  std::string screenshot;  // PNG of the reconstructed scene coloured by error; empty: none
};

// The reconstructed scene (the scanner's default method), coloured by each point's error.
void WriteDemoScreenshot(const std::filesystem::path& log, const std::string& png) {
  viewer::Scene scene;
  mapping::ReconstructionOptions options;
  options.table_cache = TableCache();
  viewer::AddDiveLog(log, options, scene);
  viewer::RenderOptions render;
  render.colour = viewer::ColourMode::kError;
  const viewer::PictureInfo info = viewer::SaveScreenshot(scene, render, png);
  std::printf(
      "\n%s: the reconstructed scene, %zu points coloured by error against truth (%.3g .. %.3g "
      "mm)\n",
      png.c_str(), info.points_drawn, info.range->lo * 1e3, info.range->hi * 1e3);
}

void RunDemo(DemoArgs a) {
  if (a.scene.empty()) a.scene = (DataFolder() / "scenes" / "default.yaml").string();
  if (!std::filesystem::is_regular_file(a.scene))
    throw Error("--scene " + a.scene + ": no such file");
  if (!a.screenshot.empty()) viewer::RequireDisplay();  // before the run, not after it
  const scanner::sim::Scene scene = scanner::sim::LoadScene(a.scene);
  const scanner::sim::Simulator simulator(scene);
  bench::ScratchFolder scratch("demo");
  const std::filesystem::path log_path = scratch.path() / "dive.db";
  mapping::DiveSimulationOptions options;
  options.threads = a.threads;
  options.producer = std::string("uwscan demo ") + UWSCAN_VERSION;
  mapping::DiveSimulationSummary summary;
  {
    ProgressBar bar;
    summary = mapping::SimulateDive(simulator, ReadText(a.scene), log_path, options,
                                    [&bar](double f) { bar.Update("simulate", f); });
  }
  std::printf(
      "Scene %s: %s scanner, %zu objects, %lld frames, %lld stripe peaks (%s), simulated in %.2f "
      "s\n\n",
      a.scene.c_str(), scanner::ToString(scene.scanner.model.kind()), scene.objects.size(),
      static_cast<long long>(summary.frames), static_cast<long long>(summary.peaks),
      scene.effects.AnyImageStage() ? "detected in rendered frames" : "exact", summary.seconds);

  std::vector<scanner::TriangulationMethod> methods = {scanner::TriangulationMethod::kRayPlane};
  if (scene.scanner.model.kind() == scanner::ScannerKind::kGalvo) {
    methods.push_back(scanner::TriangulationMethod::kRayCone);
    methods.push_back(scanner::TriangulationMethod::kRayRay);
  }
  const mapping::DiveLogReader log(log_path);
  std::printf(
      "| method | points | mean err mm | std mm | max err mm | tables s | triangulation s | M "
      "points/s |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const scanner::TriangulationMethod method : methods) {
    mapping::ReconstructionOptions ro;
    ro.method = method;
    ro.table_cache = TableCache();
    const mapping::Reconstruction r = mapping::Reconstruct(log, ro);
    const std::optional<mapping::TruthError> e = mapping::CompareToTruth(r);
    if (!e) throw Error("demo: the simulated log has no ground truth");
    std::printf(
        "| %s | %zu | %.3g | %.3g | %.3g | %.3f | %.4f | %.2f |\n", scanner::ToString(method),
        r.points.size(), e->mean_m * 1e3, e->std_m * 1e3, e->max_m * 1e3, r.table_seconds,
        r.triangulation_seconds,
        r.triangulation_seconds > 0 ? 1e-6 * r.points.size() / r.triangulation_seconds : 0.0);
  }
  std::printf(
      "\nErrors are distances from each reconstructed point to the true surface point of its\n"
      "stripe peak. Ray-plane ignores the refraction of the laser plane into a cone; ray-cone\n"
      "fits that cone per mirror step; ray-ray solves the exact refracted rays.\n");
  if (!a.screenshot.empty()) WriteDemoScreenshot(log_path, a.screenshot);
}

}  // namespace

void AddDemoCommand(CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "demo", "simulate the default scene, reconstruct it with every method, compare to truth");
  cmd->add_option(
      "--scene", args->scene,
      "scene YAML (default: scenes/default.yaml in the data folder, `uwscan --data-dir`)");
  cmd->add_option("--threads", args->threads, "frames simulated in parallel (0: all cores)")
      ->check(kNonNegativeNumber);
  cmd->add_option(
      "--screenshot", args->screenshot,
      "also write a PNG of the reconstructed scene coloured by error (needs an X display)");
  cmd->callback([args] { RunDemo(*args); });
}

}  // namespace uwscan::app
