#include "apps/bench/long_dive_bench_report.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/slam/long_dive_benchmark.hpp"

namespace uwscan::app {
namespace {

nlohmann::json TimesJson(const bench::SubmapTimes& t) {
  return {{"median", t.median_s}, {"p95", t.p95_s}};
}

nlohmann::json StagesJson(const mapping::MapperStageSeconds& s) {
  return {{"triangulation", s.triangulation_s},
          {"submap", s.submap_s},
          {"registration", s.registration_s},
          {"loop", s.loop_s},
          {"graph", s.graph_s}};
}

nlohmann::json RunJson(const bench::LongDiveRun& r) {
  return {{"seconds", r.seconds},
          {"real_time_factor", r.real_time_factor},
          {"ate_m", r.ate_m},
          {"map_rms_m", r.map_rms_m},
          {"submap_seconds",
           {{"first_tenth", TimesJson(r.first_tenth)}, {"last_tenth", TimesJson(r.last_tenth)}}},
          {"stage_seconds_mean",
           {{"first_tenth", StagesJson(r.first_tenth_stages)},
            {"last_tenth", StagesJson(r.last_tenth_stages)}}},
          {"rss_bytes_at_start", r.rss_bytes_at_start},
          {"peak_rss_bytes", r.peak_rss_bytes},
          {"rss_bytes_last_tenth", r.rss_bytes_last_tenth},
          {"heap_in_use_bytes_last_tenth", r.heap_in_use_bytes_last_tenth},
          {"heap_held_bytes_last_tenth", r.heap_held_bytes_last_tenth},
          {"loops_accepted", r.loops_accepted},
          {"loops_false", r.loops_false},
          {"loops_missed", r.loops_missed},
          {"registrations_missed", r.registrations_missed},
          {"whole_solves", r.whole_solves},
          {"whole_solves_beside", r.whole_solves_beside},
          {"window_solves", r.window_solves},
          {"loop_window_solves", r.loop_window_solves},
          {"series",
           {{"submap_time_s", r.submap_time_s},
            {"submap_seconds", r.submap_seconds},
            {"rss_time_s", r.rss_time_s},
            {"rss_bytes", r.rss_bytes},
            {"heap_in_use_bytes", r.heap_in_use_bytes},
            {"heap_held_bytes", r.heap_held_bytes}}}};
}

// The layout: today's mapper's figures at the top of each dive, the whole-graph solves'
// under "full_solve".
nlohmann::json DiveJson(const bench::LongDiveFigures& f) {
  nlohmann::json dive = RunJson(f.windowed);
  dive["name"] = f.name;
  dive["seed"] = f.seed;
  dive["duration_s"] = f.duration_s;
  dive["submaps"] = f.submaps;
  dive["dead_reckoning_ate_m"] = f.dead_reckoning_ate_m;
  dive["full_solve"] = f.whole ? RunJson(*f.whole) : nlohmann::json(nullptr);
  return dive;
}

void PrintRow(const char* method, const bench::LongDiveRun& r) {
  std::printf(
      "| %s | %.1f / %.1f ms | %.1f / %.1f ms | %.0f / %.0f MB | %.0f MB | %.0f / %.0f MB | %.1fx "
      "| "
      "%.1f mm | %.2f mm | %d (%d, %d) | %d (%d beside) + %d (%d back to a loop) |\n",
      method, r.first_tenth.median_s * 1e3, r.first_tenth.p95_s * 1e3, r.last_tenth.median_s * 1e3,
      r.last_tenth.p95_s * 1e3, static_cast<double>(r.rss_bytes_at_start) / 1e6,
      static_cast<double>(r.peak_rss_bytes) / 1e6,
      static_cast<double>(r.rss_bytes_last_tenth) / 1e6,
      static_cast<double>(r.heap_in_use_bytes_last_tenth) / 1e6,
      static_cast<double>(r.heap_held_bytes_last_tenth) / 1e6, r.real_time_factor, r.ate_m * 1e3,
      r.map_rms_m * 1e3, r.loops_accepted, r.loops_false, r.loops_missed, r.whole_solves,
      r.whole_solves_beside, r.window_solves, r.loop_window_solves);
}

void PrintStages(const std::string& name, const bench::LongDiveRun& r) {
  const mapping::MapperStageSeconds &a = r.first_tenth_stages, &b = r.last_tenth_stages;
  std::printf(
      "%s: triangulation %.1f -> %.1f, submap %.1f -> %.1f, registration %.1f -> %.1f, loops "
      "%.1f -> %.1f, graph %.1f -> %.1f\n",
      name.c_str(), a.triangulation_s * 1e3, b.triangulation_s * 1e3, a.submap_s * 1e3,
      b.submap_s * 1e3, a.registration_s * 1e3, b.registration_s * 1e3, a.loop_s * 1e3,
      b.loop_s * 1e3, a.graph_s * 1e3, b.graph_s * 1e3);
}

// Per dive length over its seeds: the windowed solves' ATE and map RMS against the whole-graph
// solves' (mean ratio, and the range), the last tenth's median time per submap against the
// first's, the lowest real-time factor.
void PrintOverSeeds(const std::vector<bench::LongDiveFigures>& dives) {
  std::printf(
      "\nover the seeds (windowed against whole-graph solves):\n"
      "| dive | seeds | ATE ratio: mean (range) | map RMS ratio: mean (range) | last / first tenth "
      "(range) | real time, lowest |\n|---|---:|---:|---:|---:|---:|\n");
  std::map<std::string, std::vector<const bench::LongDiveFigures*>> by_name;
  for (const bench::LongDiveFigures& f : dives)
    if (f.whole) by_name[f.name].push_back(&f);
  for (const auto& [name, runs] : by_name) {
    std::vector<double> ate, rms, growth;
    double slowest = std::numeric_limits<double>::infinity();
    for (const bench::LongDiveFigures* f : runs) {
      ate.push_back(f->windowed.ate_m / f->whole->ate_m);
      rms.push_back(f->windowed.map_rms_m / f->whole->map_rms_m);
      growth.push_back(f->windowed.last_tenth.median_s / f->windowed.first_tenth.median_s);
      slowest = std::min(slowest, f->windowed.real_time_factor);
    }
    const auto summary = [](const std::vector<double>& v) {
      char text[64];
      std::snprintf(text, sizeof text, "%.3f (%.3f-%.3f)",
                    std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()),
                    *std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end()));
      return std::string(text);
    };
    std::printf("| %s | %zu | %s | %s | %s | %.1fx |\n", name.c_str(), runs.size(),
                summary(ate).c_str(), summary(rms).c_str(), summary(growth).c_str(), slowest);
  }
}

}  // namespace

void RunLongDiveBench(const std::vector<double>& minutes, int threads, bool whole_solves,
                      double whole_solve_lag_s, int seeds, const std::string& json) {
  bench::LongDiveBenchOptions options;
  options.minutes = minutes;
  options.threads = threads;
  options.whole_solves = whole_solves;
  options.whole_solve_lag_s = whole_solve_lag_s;
  options.seeds = seeds;
  options.scenes_folder = DataFolder() / "scenes";
  options.table_cache = TableCache();
  std::vector<bench::LongDiveFigures> dives;
  {
    ProgressBar bar;
    dives = bench::RunLongDiveBench(options, bar.Callback());
  }
  std::printf(
      "| dive | solves | time per submap, first tenth: median / p95 | last tenth | RSS at start / "
      "peak | RSS, last tenth | heap in use / held, last tenth | real time | ATE | map RMS | loops "
      "(false, right ones rejected) | whole + window solves (back to a loop) |\n"
      "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  nlohmann::json out = {{"bench", "slam_long"},
                        {"whole_solve_lag_s", whole_solve_lag_s},
                        {"dives", nlohmann::json::array()}};
  for (const bench::LongDiveFigures& f : dives) {
    std::printf(
        "| %s, seed %llu (%.0f s, %d submaps, dead reckoning ATE %.1f mm) | | | | | | | | | | | "
        "|\n",
        f.name.c_str(), static_cast<unsigned long long>(f.seed), f.duration_s, f.submaps,
        f.dead_reckoning_ate_m * 1e3);
    PrintRow("windowed", f.windowed);
    if (f.whole) PrintRow("whole graph", *f.whole);
    out["dives"].push_back(DiveJson(f));
  }
  std::printf("\nmean ms per submap by stage, first tenth -> last tenth (windowed):\n");
  for (const bench::LongDiveFigures& f : dives)
    PrintStages(f.name + " seed " + std::to_string(f.seed), f.windowed);
  if (seeds > 1) PrintOverSeeds(dives);
  if (!json.empty()) WriteJsonFile(json, out);
}

}  // namespace uwscan::app
