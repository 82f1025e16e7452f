#include "apps/slam_bench_command.hpp"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/data_cache.hpp"
#include "apps/json_output.hpp"
#include "apps/progress_bar.hpp"
#include "bench/slam_benchmark.hpp"

namespace uwscan::app {
namespace {

struct SlamBenchArgs {
  std::vector<std::string> scenes = {"data/scenes/inspection_loop.yaml", "data/scenes/inspection_pipe.yaml"};
  std::string json;
  int threads = 2;
  bool no_open3d = false;
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
  std::printf("\n%s: %.0f s dive, %d submaps, simulated in %.1f s\n", f.name.c_str(), f.duration_s, f.submaps,
              f.simulate_seconds);
  std::printf("| | ATE | RPE per m | map to surfaces: mean | rms | p95 | seconds |\n|---|---:|---:|---:|---:|---:|---:|\n");
  const auto row = [](const char* name, const bench::TrajectoryFigures& t) {
    std::printf("| %s | %.4f m | %.4f | %.2f mm | %.2f mm | %.2f mm | %.2f |\n", name, t.ate_m, t.rpe_per_m.value_or(NAN),
                t.map.mean_m * 1e3, t.map.rms_m * 1e3, t.map.p95_m * 1e3, t.seconds);
  };
  row("dead reckoning", f.dead_reckoning);
  row("uwscan SLAM", f.slam);
  if (f.open3d) row("Open3D multiway", *f.open3d);
  const bench::SurfaceDistance& floor = f.true_poses_map;
  std::printf("| true poses (the sensor's floor) | | | %.2f mm | %.2f mm | %.2f mm | |\n", floor.mean_m * 1e3,
              floor.rms_m * 1e3, floor.p95_m * 1e3);
  std::printf("SLAM/DR: ATE %.3f, map rms %.3f; loops accepted %d (false %d), rejected %d; NEES %.2f (6 = consistent); "
              "%.1fx real time\n",
              f.slam.ate_m / f.dead_reckoning.ate_m, f.slam.map.rms_m / f.dead_reckoning.map.rms_m, f.loops_accepted,
              f.loops_false, f.loops_rejected, f.nees_mean.value_or(NAN), f.real_time_factor);
  if (f.open3d) {
    std::printf("uwscan vs Open3D: ATE %.3f, time %.3f (uwscan's whole pipeline from the log vs Open3D's "
                "registration and optimisation of the finished submaps)\n",
                f.slam.ate_m / f.open3d->ate_m, f.slam.seconds / f.open3d->seconds);
  }
}

void RunSlamBench(const SlamBenchArgs& a) {
  bench::SlamBenchOptions options;
  for (const std::string& s : a.scenes) options.scenes.emplace_back(s);
  options.threads = a.threads;
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
    slam["nees_mean"] = f.nees_mean ? nlohmann::json(*f.nees_mean) : nlohmann::json(nullptr);
    slam["real_time_factor"] = f.real_time_factor;
    nlohmann::json dive = {{"name", f.name},
                           {"duration_s", f.duration_s},
                           {"submaps", f.submaps},
                           {"threads", a.threads},
                           {"dr", TrajectoryJson(f.dead_reckoning)},
                           {"slam", slam},
                           {"true_poses_map", MapJson(f.true_poses_map)}};
    dive["open3d"] = f.open3d ? TrajectoryJson(*f.open3d) : nlohmann::json(nullptr);
    json["dives"].push_back(dive);
  }
  if (!a.json.empty()) WriteJsonFile(a.json, json);
}

}  // namespace

void AddSlamBenchCommand(CLI::App& bench) {
  auto a = std::make_shared<SlamBenchArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "slam", "scan-matching SLAM against dead reckoning and Open3D's multiway registration on simulated dives");
  cmd->add_option("--scene", a->scenes, "dive scenes (default: data/scenes/inspection_loop.yaml and inspection_pipe.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--threads", a->threads, "threads")->check(CLI::PositiveNumber);
  cmd->add_flag("--no-open3d", a->no_open3d, "skip Open3D's pipeline");
  cmd->add_option("--json", a->json, "write the figures as JSON");
  cmd->callback([a] { RunSlamBench(*a); });
}

}  // namespace uwscan::app
