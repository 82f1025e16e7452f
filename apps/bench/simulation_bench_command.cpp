#include "apps/bench/simulation_bench_command.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/cpu_model.hpp"
#include "bench/scanner/simulation_benchmark.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::app {
namespace {

struct SimulationBenchArgs {
  std::string json_path;
  std::string data_dir;  // empty: DataFolder()
  int frames = 12;
};

void RunSimulationBench(const SimulationBenchArgs& a) {
  if (!a.json_path.empty()) {
    const std::filesystem::path parent = std::filesystem::path(a.json_path).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw Error("--json " + a.json_path + ": folder '" + parent.string() + "' does not exist");
    }
  }
  bench::SimulationBenchOptions o;
  o.data_dir = DataFolderOr(a.data_dir);
  o.frames = a.frames;
  bench::SimulationBenchResult r;
  {
    ProgressBar bar;
    r = bench::RunSimulationBenchmark(o, bar.Callback());
  }
  std::printf(
      "Simulation cost per effect: %d frames of each scene (galvo: scenes/default.yaml, "
      "MEMS: scenes/mems_plane.yaml), one thread, fastest of 3 passes; each effect alone on, all "
      "others off\n\n",
      r.frames);
  std::printf("| scene | effect | ms / frame | x all off | peaks |\n|---|---|---:|---:|---:|\n");
  nlohmann::json rows = nlohmann::json::array();
  for (const bench::EffectCost& c : r.rows) {
    std::printf("| %s | %s | %.3f | %.2f | %lld |\n", c.scene.c_str(), c.effect.c_str(),
                c.ms_per_frame, c.ratio_to_none, static_cast<long long>(c.peaks));
    rows.push_back({{"scene", c.scene},
                    {"effect", c.effect},
                    {"ms_per_frame", c.ms_per_frame},
                    {"ratio_to_none", c.ratio_to_none},
                    {"peaks", c.peaks}});
  }
  std::printf(
      "\nCPU: %s. \"off_with_parameters\": every effect off, every parameter changed: an off\n"
      "stage must cost nothing (ratio ~1). Image stages render and search 2048x1088 frames.\n",
      bench::CpuModel().c_str());
  if (!a.json_path.empty()) {
    WriteJsonFile(a.json_path, {{"frames", r.frames}, {"rows", rows}, {"cpu", bench::CpuModel()}});
  }
}

}  // namespace

void AddSimulationBenchCommand(CLI::App& bench) {
  auto args = std::make_shared<SimulationBenchArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "simulation", "time per frame of each simulation effect, alone and all on");
  cmd->add_option("--json", args->json_path, "write the figures as JSON");
  cmd->add_option("--data", args->data_dir,
                  "data folder holding scenes/ (default: `uwscan --data-dir`)");
  cmd->add_option("--frames", args->frames, "frames timed per row")->check(kPositiveNumber);
  cmd->callback([args] { RunSimulationBench(*args); });
}

}  // namespace uwscan::app
