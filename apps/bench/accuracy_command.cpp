#include "apps/bench/accuracy_command.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/scanner/accuracy_benchmark.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::app {
namespace {

struct AccuracyArgs {
  std::string json_path;
  std::string data_dir;  // empty: DataFolder()
  bool quick = false;
  std::uint64_t seed = 1;
  int threads = 0;
};

nlohmann::json GaugeJson(const bench::GaugeFigures& g) {
  return {{"mean_err_m", g.mean_err_m},
          {"std_err_m", g.std_err_m},
          {"n", g.n},
          {"bias_m", g.bias_m},
          {"missed", g.missed}};
}

nlohmann::json PeakJson(const bench::PeakErrorFigures& f) {
  return {{"std_px", f.std_px},
          {"rms_px", f.rms_px},
          {"bias_px", f.bias_px},
          {"p95_abs_px", f.p95_abs_px},
          {"peaks", f.peaks}};
}

bench::AccuracyBenchOptions AccuracyOptionsOf(const AccuracyArgs& a) {
  bench::AccuracyBenchOptions o;
  const std::filesystem::path data = DataFolderOr(a.data_dir);
  o.galvo_scanner = data / "scanners" / "galvo_default.yaml";
  o.mems_scanner = data / "scanners" / "mems_default.yaml";
  o.seed = a.seed;
  o.threads = a.threads;
  if (a.quick) {  // a smoke run: every experiment, a few positions each
    o.gauge_positions = 3;
    o.plane_distances_m = {1.25};
    o.sphere_distances_m = {1.0};
    o.waypoints_per_line = {5, 50};
    o.mems_lines = 20;
  }
  return o;
}

void PrintGauges(const bench::AccuracyBenchOptions& o, const bench::AccuracyBenchResult& r) {
  std::printf(
      "Seed 000 gauges (galvanometer scanner, %d positions %.2f-%.2f m, lengths 20/50/100 mm):\n\n",
      o.gauge_positions, o.gauge_near_m, o.gauge_far_m);
  std::printf(
      "| medium | mean abs err mm | std mm | bias mm | gauges | missed | exact peaks: mean abs / "
      "bias mm | seed mean / std mm |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---|\n");
  const auto gauge_row = [](const char* medium, const bench::GaugeFigures& g,
                            const bench::GaugeFigures& exact, const char* seed) {
    std::printf("| %s | %.3f | %.3f | %.3f | %d | %d | %.3f / %.3f | %s |\n", medium,
                g.mean_err_m * 1e3, g.std_err_m * 1e3, g.bias_m * 1e3, g.n, g.missed,
                exact.mean_err_m * 1e3, exact.bias_m * 1e3, seed);
  };
  gauge_row("air", r.gauges_air, r.gauges_air_exact, "0.44 / 0.35");
  gauge_row("water", r.gauges_water, r.gauges_water_exact, "0.98 / 0.72");
  std::printf("\n");
}

nlohmann::json PrintPlane(const bench::AccuracyBenchOptions& o,
                          const bench::AccuracyBenchResult& r) {
  nlohmann::json plane = nlohmann::json::array();
  std::printf("Seed 001 plane (MEMS scanner, %d lines x 50 waypoints, under water):\n\n",
              o.mems_lines);
  std::printf("| distance m | plane rms mm | points |\n|---:|---:|---:|\n");
  for (const bench::PlaneRow& row : r.plane) {
    std::printf("| %.2f | %.3f | %lld |\n", row.distance_m, row.rms_m * 1e3,
                static_cast<long long>(row.points));
    plane.push_back({{"distance_m", row.distance_m}, {"rms_m", row.rms_m}, {"points", row.points}});
  }
  return plane;
}

nlohmann::json PrintSphere(const bench::AccuracyBenchOptions& o,
                           const bench::AccuracyBenchResult& r) {
  nlohmann::json sphere = nlohmann::json::array();
  std::printf("\nSeed 001 sphere (radius %.0f mm):\n\n", o.sphere_radius_m * 1e3);
  std::printf("| distance m | radius err mm | fit rms mm | points |\n|---:|---:|---:|---:|\n");
  for (const bench::SphereRow& row : r.sphere) {
    std::printf("| %.2f | %.3f | %.3f | %lld |\n", row.distance_m, row.radius_err_m * 1e3,
                row.rms_m * 1e3, static_cast<long long>(row.points));
    sphere.push_back({{"distance_m", row.distance_m},
                      {"radius_err_m", row.radius_err_m},
                      {"rms_m", row.rms_m},
                      {"points", row.points}});
  }
  return sphere;
}

nlohmann::json PrintWaypoints(const bench::AccuracyBenchOptions& o,
                              const bench::AccuracyBenchResult& r) {
  nlohmann::json waypoints = nlohmann::json::array();
  std::printf(
      "\nSeed 001 waypoints per line (plane at %.2f m; seed: ~70 lines/s, 140 k points/s at "
      "50):\n\n",
      o.waypoint_plane_distance_m);
  std::printf(
      "| waypoints/line | plane rms mm | rms mm, exact peaks | lines/s | points/s "
      "|\n|---:|---:|---:|---:|---:|\n");
  for (const bench::WaypointRow& row : r.waypoints) {
    std::printf("| %d | %.3f | %.4f | %.1f | %.0f |\n", row.waypoints_per_line, row.rms_m * 1e3,
                row.rms_noise_free_m * 1e3, row.lines_per_s, row.points_per_s);
    waypoints.push_back({{"waypoints_per_line", row.waypoints_per_line},
                         {"rms_m", row.rms_m},
                         {"rms_noise_free_m", row.rms_noise_free_m},
                         {"lines_per_s", row.lines_per_s},
                         {"points_per_s", row.points_per_s}});
  }
  return waypoints;
}

void PrintPeakErrors(const bench::AccuracyBenchResult& r) {
  std::printf(
      "\nThe detector on the rendered stripes (detected peak minus the exact crossing of its image "
      "line):\n\n");
  std::printf(
      "| stripes | std px | rms px | bias px | p95 abs px | peaks "
      "|\n|---|---:|---:|---:|---:|---:|\n");
  const auto peak_row = [](const char* what, const bench::PeakErrorFigures& f) {
    std::printf("| %s | %.3f | %.3f | %+.3f | %.3f | %lld |\n", what, f.std_px, f.rms_px, f.bias_px,
                f.p95_abs_px, static_cast<long long>(f.peaks));
  };
  peak_row("galvanometer, gauges in water", r.peak_errors_gauges_water);
  peak_row("MEMS, plane", r.peak_errors_plane);
}

void RunAccuracy(const AccuracyArgs& a) {
  if (!a.json_path.empty()) {
    const std::filesystem::path parent = std::filesystem::path(a.json_path).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw Error("--json " + a.json_path + ": folder '" + parent.string() + "' does not exist");
    }
  }
  const bench::AccuracyBenchOptions o = AccuracyOptionsOf(a);
  bench::AccuracyBenchResult r;
  {
    ProgressBar bar;
    r = bench::RunAccuracyBenchmark(o, bar.Callback());
  }
  PrintGauges(o, r);
  const nlohmann::json plane = PrintPlane(o, r);
  const nlohmann::json sphere = PrintSphere(o, r);
  const nlohmann::json waypoints = PrintWaypoints(o, r);
  PrintPeakErrors(r);
  std::printf("\n%.1f s (`uwscan plot` draws the --json's charts).\n", r.seconds);
  if (a.json_path.empty()) return;
  WriteJsonFile(a.json_path, {{"gauges",
                               {{"air", GaugeJson(r.gauges_air)},
                                {"water", GaugeJson(r.gauges_water)},
                                {"air_exact_peaks", GaugeJson(r.gauges_air_exact)},
                                {"water_exact_peaks", GaugeJson(r.gauges_water_exact)}}},
                              {"plane", plane},
                              {"sphere", sphere},
                              {"waypoints", waypoints},
                              {"peak_errors",
                               {{"gauges_water", PeakJson(r.peak_errors_gauges_water)},
                                {"plane", PeakJson(r.peak_errors_plane)}}},
                              {"seconds", r.seconds}});
}

}  // namespace

void AddAccuracyBenchCommand(CLI::App& bench) {
  auto args = std::make_shared<AccuracyArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "accuracy",
      "the seeds' accuracy experiments in simulation: gauges, plane, sphere, waypoints");
  cmd->add_option("--json", args->json_path, "write the figures as JSON");
  cmd->add_option("--data", args->data_dir,
                  "data folder holding scanners/ (default: `uwscan --data-dir`)");
  cmd->add_flag("--quick", args->quick, "a few positions per experiment (smoke test)");
  cmd->add_option("--seed", args->seed, "noise seed");
  cmd->add_option("--threads", args->threads, "frames simulated in parallel (0: all cores)")
      ->check(kNonNegativeNumber);
  cmd->callback([args] { RunAccuracy(*args); });
}

}  // namespace uwscan::app
