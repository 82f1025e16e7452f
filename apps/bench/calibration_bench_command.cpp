#include "apps/bench/calibration_bench_command.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/scanner/calibration_benchmark.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::app {
namespace {

// The target: gauges measured with the estimated calibration within 1.5x of the error
// with the true one.
constexpr double kGaugeRatioTarget = 1.5;

struct CalibrationBenchArgs {
  std::string json_path;
  std::string data_dir;  // empty: DataFolder()
  bool quick = false;
  std::uint64_t seed = 1;
  int threads = 0;
};

nlohmann::json NumberOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

void RunCalibrationBench(const CalibrationBenchArgs& a) {
  if (!a.json_path.empty()) {
    const std::filesystem::path parent = std::filesystem::path(a.json_path).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw Error("--json " + a.json_path + ": folder '" + parent.string() + "' does not exist");
    }
  }
  bench::CalibrationBenchOptions o;
  o.data_dir = DataFolderOr(a.data_dir);
  o.seed = a.seed;
  o.threads = a.threads;
  if (a.quick) o.gauge_positions = 3;
  bench::CalibrationBenchResult r;
  {
    ProgressBar bar;
    r = bench::RunCalibrationBenchmark(o, bar.Callback());
  }
  nlohmann::json steps = nlohmann::json::object();
  for (const bench::StepFigures& step : r.steps) {
    std::printf(
        "Step %s: residual rms %.4g %s, calibration %.2f s (dataset simulated in %.1f s)\n\n",
        step.step.c_str(), step.residual_rms, step.residual_unit.c_str(), step.seconds,
        step.dataset_seconds);
    std::printf(
        "| parameter | true | estimated | std | error / std |\n|---|---:|---:|---:|---:|\n");
    nlohmann::json params = nlohmann::json::object();
    for (const bench::ParameterFigure& p : step.params) {
      const double error = p.estimated - p.truth;
      const std::string ratio =
          std::isfinite(error) && p.std > 0.0 ? std::to_string(error / p.std).substr(0, 6) : "-";
      std::printf("| %s | %.9g | %.9g | %.3g | %s |\n", p.name.c_str(), p.truth, p.estimated, p.std,
                  ratio.c_str());
      params[p.name] = {{"true", NumberOrNull(p.truth)},
                        {"estimated", NumberOrNull(p.estimated)},
                        {"std", p.std}};
    }
    std::printf("\n");
    steps[step.step] = {{"params", params},
                        {"residual_rms", step.residual_rms},
                        {"residual_unit", step.residual_unit},
                        {"seconds", step.seconds},
                        {"dataset_seconds", step.dataset_seconds}};
  }
  const double ratio =
      r.gauges_estimated_calibration_mean_err_m / r.gauges_true_calibration_mean_err_m;
  std::printf(
      "Gauges under water (%d measured): mean abs length error %.3f mm with the true calibration, "
      "%.3f mm with the estimated one (%.2fx; target <= %.1fx: %s)\n",
      r.gauges, r.gauges_true_calibration_mean_err_m * 1e3,
      r.gauges_estimated_calibration_mean_err_m * 1e3, ratio, kGaugeRatioTarget,
      ratio <= kGaugeRatioTarget ? "met" : "missed");
  std::printf("%.1f s\n", r.seconds);
  if (!a.json_path.empty()) {
    WriteJsonFile(
        a.json_path,
        {{"steps", steps},
         {"gauges",
          {{"true_calibration_mean_err_m", r.gauges_true_calibration_mean_err_m},
           {"estimated_calibration_mean_err_m", r.gauges_estimated_calibration_mean_err_m},
           {"gauges", r.gauges}}},
         {"seconds", r.seconds}});
  }
}

}  // namespace

void AddCalibrationBenchCommand(CLI::App& bench) {
  auto args = std::make_shared<CalibrationBenchArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "calibration", "every calibration step on simulated datasets: recovered vs true, and gauges");
  cmd->add_option("--json", args->json_path, "write the figures as JSON");
  cmd->add_option("--data", args->data_dir,
                  "data folder holding scenes/ and scanners/ (default: `uwscan --data-dir`)");
  cmd->add_flag("--quick", args->quick, "3 gauge positions instead of 29 (smoke test)");
  cmd->add_option("--seed", args->seed, "noise seed of the gauge experiment");
  cmd->add_option("--threads", args->threads, "threads (0: all cores)")->check(kNonNegativeNumber);
  cmd->callback([args] { RunCalibrationBench(*args); });
}

}  // namespace uwscan::app
