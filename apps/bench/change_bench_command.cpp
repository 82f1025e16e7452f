#include "apps/bench/change_bench_command.hpp"

#include <cstdio>
#include <memory>
#include <string>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/change/change_benchmark.hpp"

namespace uwscan::app {
namespace {

struct ChangeBenchArgs {
  std::string json;
  int threads = 2;
  bool no_cloudcompare = false;
};

nlohmann::json MethodJson(const bench::MethodFigures& m) {
  nlohmann::json depths = nlohmann::json::object();
  for (const auto& [mm, d] : m.by_depth_mm) {
    depths[std::to_string(mm)] = {{"changes", d.changes},
                                  {"detection_rate", d.detection_rate},
                                  {"false_area_share", d.false_area_share}};
  }
  nlohmann::json changes = nlohmann::json::array();
  for (const bench::ChangeOutcome& c : m.changes)
    changes.push_back({{"name", c.name}, {"points", c.points}, {"found", c.found}});
  return {{"by_depth_mm", depths},
          {"changes", changes},
          {"unchanged_flagged_share", m.unchanged_flagged_share},
          {"unchanged_rms_m", m.unchanged_rms_m},
          {"changed_rms_error_m", m.changed_rms_error_m},
          {"threshold_m", m.threshold_m ? nlohmann::json(*m.threshold_m) : nlohmann::json(nullptr)},
          {"seconds", m.seconds}};
}

void Print(const bench::ChangeFigures& f) {
  std::printf("maps: %.2f mm RMS to their true surfaces; simulated in %.1f s, mapped in %.1f s\n\n",
              1e3 * f.map_rms_m, f.simulate_seconds, f.map_seconds);
  std::printf(
      "| method | detected at 2 / 5 / 10 / 20 mm | false area | unchanged flagged | "
      "unchanged RMS | error on changes | threshold | seconds |\n"
      "|---|---|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [name, m] : f.methods) {
    std::string rates;
    double false_share = 0.0;
    for (const auto& [mm, d] : m.by_depth_mm) {
      char rate[32];
      std::snprintf(rate, sizeof rate, "%s%.0f %%", rates.empty() ? "" : " / ",
                    100.0 * d.detection_rate);
      rates += rate;
      false_share = d.false_area_share;
    }
    char threshold[32] = "";
    if (m.threshold_m) std::snprintf(threshold, sizeof threshold, "%.2f mm", 1e3 * *m.threshold_m);
    std::printf("| %s | %s | %.2f %% | %.1f %% | %.2f mm | %.2f mm | %s | %.2f |\n", name.c_str(),
                rates.c_str(), 100.0 * false_share, 100.0 * m.unchanged_flagged_share,
                1e3 * m.unchanged_rms_m, 1e3 * m.changed_rms_error_m, threshold, m.seconds);
  }
  if (!f.cloudcompare_ran)
    std::printf("\nCloudCompare not run (not installed, or --no-cloudcompare)\n");
}

void RunChangeBench(const ChangeBenchArgs& a) {
  bench::ChangeBenchOptions options;
  options.before_scene = DataFolder() / "scenes" / "change_before.yaml";
  options.after_scene = DataFolder() / "scenes" / "change_after.yaml";
  options.threads = a.threads;
  options.run_cloudcompare = !a.no_cloudcompare;
  options.table_cache = TableCache();
  bench::ChangeFigures f;
  {
    ProgressBar bar;
    f = bench::RunChangeBench(options, bar.Callback());
  }
  Print(f);
  if (a.json.empty()) return;
  nlohmann::json methods = nlohmann::json::object();
  for (const auto& [name, m] : f.methods) methods[name] = MethodJson(m);
  WriteJsonFile(a.json, {{"methods", methods},
                         {"map_rms_m", f.map_rms_m},
                         {"simulate_seconds", f.simulate_seconds},
                         {"map_seconds", f.map_seconds},
                         {"cloudcompare_ran", f.cloudcompare_ran}});
}

}  // namespace

void AddChangeBenchCommand(CLI::App& bench) {
  auto a = std::make_shared<ChangeBenchArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "change",
      "what the inspection found against the truth: two simulated surveys (change_before.yaml, "
      "change_after.yaml), SLAM maps, changes of 2-20 mm; uwscan compare beside CloudCompare's "
      "cloud-to-cloud and cloud-to-mesh distances and the nearest-neighbour distance");
  cmd->add_option("--threads", a->threads, "threads")->check(kPositiveNumber);
  cmd->add_flag("--no-cloudcompare", a->no_cloudcompare, "skip CloudCompare");
  cmd->add_option("--json", a->json, "write the figures as JSON");
  cmd->callback([a] { RunChangeBench(*a); });
}

}  // namespace uwscan::app
