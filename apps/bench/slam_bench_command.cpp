#include "apps/bench/slam_bench_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/bench/long_dive_bench_report.hpp"
#include "apps/cli/data_cache.hpp"
#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/malloc_arena.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/slam/slam_benchmark.hpp"

namespace uwscan::app {
namespace {

struct SlamBenchArgs {
  std::vector<std::string> scenes;  // empty: DefaultScenes()
  std::string json;
  int seeds = 1;
  int threads = 2;
  double walk_scale = 1.0;
  bool no_open3d = false;
  bool long_dives = false;
  std::vector<double> minutes = {4.0, 15.0, 30.0};
  bool no_whole_solves = false;
  double whole_solve_lag_s = mapping::MapperOptions{}.whole_solve_lag_s;
};

nlohmann::json MapJson(const bench::SurfaceDistance& d) {
  return {{"mean_m", d.mean_m}, {"rms_m", d.rms_m}, {"p95_m", d.p95_m}, {"points", d.points}};
}

nlohmann::json TrajectoryJson(const bench::TrajectoryFigures& t) {
  return {{"ate_m", t.ate_m},
          {"rpe_per_m", t.rpe_per_m ? nlohmann::json(*t.rpe_per_m) : nlohmann::json(nullptr)},
          {"map_rms_m", t.map.rms_m},
          {"map", MapJson(t.map)},
          {"seconds", t.seconds}};
}

void Print(const bench::DiveFigures& f) {
  std::printf("\n%s (seed %llu): %.0f s dive, %d submaps, simulated in %.1f s\n", f.name.c_str(),
              static_cast<unsigned long long>(f.seed), f.duration_s, f.submaps, f.simulate_seconds);
  std::printf(
      "| | ATE | RPE per m | map to surfaces: mean | rms | p95 | seconds "
      "|\n|---|---:|---:|---:|---:|---:|---:|\n");
  const auto row = [](const char* name, const bench::TrajectoryFigures& t) {
    std::printf("| %s | %.4f m | %.4f | %.2f mm | %.2f mm | %.2f mm | %.2f |\n", name, t.ate_m,
                t.rpe_per_m.value_or(NAN), t.map.mean_m * 1e3, t.map.rms_m * 1e3, t.map.p95_m * 1e3,
                t.seconds);
  };
  row("dead reckoning", f.dead_reckoning);
  row("uwscan SLAM", f.slam);
  if (f.open3d) row("Open3D multiway", *f.open3d);
  const bench::SurfaceDistance& floor = f.true_poses_map;
  std::printf("| true poses (the sensor's floor) | | | %.2f mm | %.2f mm | %.2f mm | |\n",
              floor.mean_m * 1e3, floor.rms_m * 1e3, floor.p95_m * 1e3);
  std::printf(
      "SLAM/DR: ATE %.3f, map rms %.3f; loops accepted %d (false %d), rejected %d (right but "
      "inconsistent with the prediction %d); right registrations inconsistent with the "
      "navigation %d; NEES %.2f (6 = consistent); %.1fx real time\n",
      f.slam.ate_m / f.dead_reckoning.ate_m, f.slam.map.rms_m / f.dead_reckoning.map.rms_m,
      f.loops_accepted, f.loops_false, f.loops_rejected, f.loops_missed, f.registrations_missed,
      f.nees_mean.value_or(NAN), f.real_time_factor);
  if (f.expected_map_error_m) {
    std::printf(
        "SLAM map rms %.2f mm; its poses' covariance predicts %.2f mm (what the navigation and the "
        "scene "
        "allow)\n",
        f.slam.map.rms_m * 1e3, *f.expected_map_error_m * 1e3);
  }
  if (f.expected_ate_m) {
    std::printf("SLAM ATE %.1f mm; its poses' covariance predicts %.1f mm\n", f.slam.ate_m * 1e3,
                *f.expected_ate_m * 1e3);
  }
  if (f.open3d) {
    std::printf(
        "uwscan vs Open3D: ATE %.3f, time %.3f (uwscan's whole pipeline from the log vs Open3D's "
        "registration and optimisation of the finished submaps)\n",
        f.slam.ate_m / f.open3d->ate_m, f.slam.seconds / f.open3d->seconds);
  }
}

// Means over the seeds of one scene (and the worst ATE ratio and real-time factor).
struct SceneSummary {
  std::string name;
  int seeds = 0;
  double ate_ratio_mean = 0.0, ate_ratio_max = 0.0;
  double ate_mean_m = 0.0, expected_ate_mean_m = 0.0;  // SLAM's, measured and predicted
  double map_rms_mean_m = 0.0, map_ratio_mean = 0.0, expected_map_error_mean_m = 0.0;
  double nees_mean = 0.0, real_time_factor_mean = 0.0, real_time_factor_min = 0.0;
  int loops_false = 0, loops_missed = 0, registrations_missed = 0;
  std::optional<double> open3d_ate_ratio_mean, open3d_time_ratio_mean;  // uwscan / Open3D
};

std::vector<SceneSummary> Summarise(const std::vector<bench::DiveFigures>& dives) {
  std::vector<SceneSummary> scenes;
  for (const bench::DiveFigures& f : dives) {
    auto it = std::find_if(scenes.begin(), scenes.end(),
                           [&](const SceneSummary& s) { return s.name == f.name; });
    if (it == scenes.end()) {
      scenes.push_back({});
      it = scenes.end() - 1;
      it->name = f.name;
      it->real_time_factor_min = f.real_time_factor;
    }
    const double ate_ratio = f.slam.ate_m / f.dead_reckoning.ate_m;
    ++it->seeds;
    it->ate_ratio_mean += ate_ratio;
    it->ate_ratio_max = std::max(it->ate_ratio_max, ate_ratio);
    it->ate_mean_m += f.slam.ate_m;
    it->expected_ate_mean_m += f.expected_ate_m.value_or(NAN);
    it->map_rms_mean_m += f.slam.map.rms_m;
    it->map_ratio_mean += f.slam.map.rms_m / f.dead_reckoning.map.rms_m;
    it->expected_map_error_mean_m += f.expected_map_error_m.value_or(NAN);
    it->nees_mean += f.nees_mean.value_or(NAN);
    it->real_time_factor_mean += f.real_time_factor;
    it->real_time_factor_min = std::min(it->real_time_factor_min, f.real_time_factor);
    it->loops_false += f.loops_false;
    it->loops_missed += f.loops_missed;
    it->registrations_missed += f.registrations_missed;
    if (f.open3d) {
      it->open3d_ate_ratio_mean =
          it->open3d_ate_ratio_mean.value_or(0.0) + f.slam.ate_m / f.open3d->ate_m;
      it->open3d_time_ratio_mean =
          it->open3d_time_ratio_mean.value_or(0.0) + f.slam.seconds / f.open3d->seconds;
    }
  }
  for (SceneSummary& s : scenes) {
    const double n = s.seeds;
    for (double* v : {&s.ate_ratio_mean, &s.ate_mean_m, &s.expected_ate_mean_m, &s.map_rms_mean_m,
                      &s.map_ratio_mean, &s.expected_map_error_mean_m, &s.nees_mean,
                      &s.real_time_factor_mean}) {
      *v /= n;
    }
    if (s.open3d_ate_ratio_mean) *s.open3d_ate_ratio_mean /= n;
    if (s.open3d_time_ratio_mean) *s.open3d_time_ratio_mean /= n;
  }
  return scenes;
}

void Print(const std::vector<SceneSummary>& scenes) {
  std::printf(
      "\nOver the seeds (means; SLAM/DR ratios; the worst ATE ratio and real-time factor):\n");
  std::printf(
      "| dive | seeds | ATE ratio (worst) | SLAM ATE | predicted ATE | map rms | map ratio | "
      "predicted map rms "
      "| NEES | real time (worst) | false loops | right loops rejected | uwscan/Open3D ATE, time "
      "|\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const SceneSummary& s : scenes) {
    std::printf(
        "| %s | %d | %.3f (%.3f) | %.1f mm | %.1f mm | %.2f mm | %.3f | %.2f mm | %.2f | %.1fx "
        "(%.1fx) | %d | %d | ",
        s.name.c_str(), s.seeds, s.ate_ratio_mean, s.ate_ratio_max, s.ate_mean_m * 1e3,
        s.expected_ate_mean_m * 1e3, s.map_rms_mean_m * 1e3, s.map_ratio_mean,
        s.expected_map_error_mean_m * 1e3, s.nees_mean, s.real_time_factor_mean,
        s.real_time_factor_min, s.loops_false, s.loops_missed);
    if (s.open3d_ate_ratio_mean) {
      std::printf("%.3f, %.2f |\n", *s.open3d_ate_ratio_mean,
                  s.open3d_time_ratio_mean.value_or(NAN));
    } else {
      std::printf("|\n");
    }
  }
}

nlohmann::json SummaryJson(const SceneSummary& s) {
  return {
      {"name", s.name},
      {"seeds", s.seeds},
      {"ate_ratio_mean", s.ate_ratio_mean},
      {"ate_ratio_max", s.ate_ratio_max},
      {"ate_mean_m", s.ate_mean_m},
      {"expected_ate_mean_m", s.expected_ate_mean_m},
      {"map_rms_mean_m", s.map_rms_mean_m},
      {"map_ratio_mean", s.map_ratio_mean},
      {"expected_map_error_mean_m", s.expected_map_error_mean_m},
      {"nees_mean", s.nees_mean},
      {"real_time_factor_mean", s.real_time_factor_mean},
      {"real_time_factor_min", s.real_time_factor_min},
      {"loops_false", s.loops_false},
      {"loops_missed", s.loops_missed},
      {"registrations_missed", s.registrations_missed},
      {"open3d_ate_ratio_mean", s.open3d_ate_ratio_mean ? nlohmann::json(*s.open3d_ate_ratio_mean)
                                                        : nlohmann::json(nullptr)},
      {"open3d_time_ratio_mean", s.open3d_time_ratio_mean
                                     ? nlohmann::json(*s.open3d_time_ratio_mean)
                                     : nlohmann::json(nullptr)}};
}

// The loop, pipe and long dives, and the loop dive with the MEMS scanner, from the data folder.
std::vector<std::filesystem::path> DefaultScenes() {
  const std::filesystem::path scenes = DataFolder() / "scenes";
  return {scenes / "inspection_loop.yaml", scenes / "inspection_pipe.yaml",
          scenes / "inspection_long.yaml", scenes / "inspection_loop_mems.yaml"};
}

void RunSlamBench(const SlamBenchArgs& a) {
  bench::SlamBenchOptions options;
  for (const std::string& s : a.scenes) options.scenes.emplace_back(s);
  if (options.scenes.empty()) options.scenes = DefaultScenes();
  options.threads = a.threads;
  options.seeds = a.seeds;
  options.walk_scale = a.walk_scale;
  options.run_open3d = !a.no_open3d;
  options.table_cache = TableCache();
  std::vector<bench::DiveFigures> dives;
  {
    ProgressBar bar;
    dives = bench::RunSlamBench(options, bar.Callback());
  }
  nlohmann::json json = {{"dives", nlohmann::json::array()}};
  for (const bench::DiveFigures& f : dives) {
    Print(f);
    nlohmann::json slam = TrajectoryJson(f.slam);
    slam["loops_accepted"] = f.loops_accepted;
    slam["loops_rejected"] = f.loops_rejected;
    slam["loops_false"] = f.loops_false;
    slam["loops_missed"] = f.loops_missed;
    slam["registrations_missed"] = f.registrations_missed;
    slam["nees_mean"] = f.nees_mean ? nlohmann::json(*f.nees_mean) : nlohmann::json(nullptr);
    slam["real_time_factor"] = f.real_time_factor;
    slam["expected_map_error_m"] =
        f.expected_map_error_m ? nlohmann::json(*f.expected_map_error_m) : nlohmann::json(nullptr);
    slam["expected_ate_m"] =
        f.expected_ate_m ? nlohmann::json(*f.expected_ate_m) : nlohmann::json(nullptr);
    nlohmann::json dive = {{"name", f.name},
                           {"seed", f.seed},
                           {"duration_s", f.duration_s},
                           {"submaps", f.submaps},
                           {"threads", a.threads},
                           {"walk_scale", a.walk_scale},
                           {"dr", TrajectoryJson(f.dead_reckoning)},
                           {"slam", slam},
                           {"true_poses_map", MapJson(f.true_poses_map)}};
    dive["open3d"] = f.open3d ? TrajectoryJson(*f.open3d) : nlohmann::json(nullptr);
    json["dives"].push_back(dive);
  }
  const std::vector<SceneSummary> scenes = Summarise(dives);
  if (a.seeds > 1) Print(scenes);
  json["summary"] = nlohmann::json::array();
  for (const SceneSummary& s : scenes) json["summary"].push_back(SummaryJson(s));
  if (!a.json.empty()) WriteJsonFile(a.json, json);
}

}  // namespace

void AddSlamBenchCommand(CLI::App& bench) {
  auto a = std::make_shared<SlamBenchArgs>();
  CLI::App* cmd = bench.add_subcommand("slam",
                                       "scan-matching SLAM against dead reckoning and Open3D's "
                                       "multiway registration on simulated dives");
  cmd->add_option("--scene", a->scenes,
                  "dive scenes (default: inspection_loop.yaml, inspection_pipe.yaml, "
                  "inspection_long.yaml and inspection_loop_mems.yaml, the loop dive with the MEMS "
                  "scanner, from scenes/ in the data folder, `uwscan --data-dir`)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seeds", a->seeds,
                  "dives per scene (with --long: per length, from seed 41): its own seed and the "
                  "next ones (default 1)")
      ->check(kPositiveNumber);
  cmd->add_option("--threads", a->threads, "threads")->check(kPositiveNumber);
  cmd->add_option("--walk-scale", a->walk_scale,
                  "multiply the navigation's random walks (position, heading) by this: what SLAM's "
                  "error owes to "
                  "them (default 1)")
      ->check(kPositiveNumber);
  cmd->add_flag("--no-open3d", a->no_open3d, "skip Open3D's pipeline");
  cmd->add_flag("--long", a->long_dives,
                "instead: mapping cost against dive length, on dives of --minutes over a manifold "
                "field, with windowed and whole-graph solves (time per submap, memory, real time, "
                "ATE, map RMS)");
  cmd->add_option("--minutes", a->minutes, "with --long: the dives' lengths (default 4 15 30)")
      ->check(kPositiveNumber);
  cmd->add_flag("--no-whole-solves", a->no_whole_solves,
                "with --long: skip the whole-graph solves beside the windowed ones");
  cmd->add_option("--whole-solve-lag", a->whole_solve_lag_s,
                  "with --long: seconds of dive after which a whole-graph solve made beside the "
                  "windowed mapping is applied (0: on the mapping thread, at once)")
      ->capture_default_str()
      ->check(kNonNegativeNumber);
  cmd->add_option("--json", a->json, "write the figures as JSON");
  cmd->callback([a] {
    if (a->long_dives) {
      if (a->whole_solve_lag_s > 0.0) UseOneMallocArena();  // as `map` and the online mapping
      RunLongDiveBench(a->minutes, a->threads, !a->no_whole_solves, a->whole_solve_lag_s, a->seeds,
                       a->json);
    } else {
      RunSlamBench(*a);
    }
  });
}

}  // namespace uwscan::app
