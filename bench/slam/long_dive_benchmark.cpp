#include "bench/slam/long_dive_benchmark.hpp"

#include <malloc.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>

#include "bench/scratch_folder.hpp"
#include "bench/slam/long_dive_scene.hpp"
#include "bench/slam/slam_benchmark.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "mapping/slam/dive_mapping.hpp"
#include "mapping/slam/map_report.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/resident_memory.hpp"
#include "scanner/sim/ray_caster.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::bench {
namespace {

constexpr int kRssSamples = 200;    // over a dive
constexpr int kTimeStretches = 60;  // the time-per-submap series' points

// The process's resident memory now (bytes), from /proc/self/statm; 0 if it cannot be read.

// The mean time per submap in each of kTimeStretches stretches of the dive (what the stretch
// cost; a median would flip between the submaps that solve and those that do not), at each
// stretch's middle submap's time.
void AddTimeSeries(const mapping::DiveMapping& m, LongDiveRun& run) {
  const std::size_t n = m.submap_seconds.size();
  const std::size_t stretch = std::max<std::size_t>(1, n / kTimeStretches);
  for (std::size_t first = 0; first + stretch <= n; first += stretch) {
    const auto begin = m.submap_seconds.begin() + static_cast<std::ptrdiff_t>(first);
    run.submap_time_s.push_back(m.slam[first + stretch / 2].time_s - m.slam.front().time_s);
    run.submap_seconds.push_back(
        std::accumulate(begin, begin + static_cast<std::ptrdiff_t>(stretch), 0.0) /
        static_cast<double>(stretch));
  }
}

// The mean of values[from..] (from < size).
std::int64_t MeanFrom(const std::vector<std::int64_t>& values, std::size_t from) {
  return std::accumulate(values.begin() + static_cast<std::ptrdiff_t>(from), values.end(),
                         std::int64_t{0}) /
         static_cast<std::int64_t>(values.size() - from);
}

// The mean of each stage's time per submap over stages[first..last) (first < last).
mapping::MapperStageSeconds MeanStages(const std::vector<mapping::MapperStageSeconds>& stages,
                                       std::size_t first, std::size_t last) {
  mapping::MapperStageSeconds sum;
  for (std::size_t i = first; i < last; ++i) sum += stages[i];
  return sum * (1.0 / static_cast<double>(last - first));
}

// Maps the log (windowed or whole solves), sampling the resident memory as it goes, and
// measures the result against the truth.
LongDiveRun MapLongDive(const std::filesystem::path& log_path,
                        const scanner::sim::RayCaster& caster, bool windowed,
                        const LongDiveBenchOptions& options, const std::string& label,
                        const Progress& progress, double* dead_reckoning_ate_m) {
  mapping::DiveMappingOptions map_options;
  map_options.mapper.threads = options.threads;
  map_options.mapper.windowed_solves = windowed;
  map_options.mapper.whole_solve_lag_s = options.whole_solve_lag_s;
  map_options.mapper.spill_folder = log_path.parent_path();
  map_options.table_cache = options.table_cache;
  omp_set_num_threads(options.threads);
  // The runs share this process: what the last one freed goes back to the system first, so each
  // run's resident memory starts from the process's own floor, not the last run's peak.
  malloc_trim(0);
  LongDiveRun run;
  run.rss_bytes_at_start = ResidentBytes().value_or(0);
  const mapping::DiveLogReader log(log_path);
  int next_sample = 0;
  std::vector<double> rss_fractions;
  const mapping::DiveMapping m = mapping::MapDive(log, map_options, [&](double fraction) {
    if (fraction * kRssSamples < next_sample) return;
    ++next_sample;
    rss_fractions.push_back(fraction);
    run.rss_bytes.push_back(ResidentBytes().value_or(0));
    const HeapBytes heap = CurrentHeapBytes();
    run.heap_in_use_bytes.push_back(heap.in_use);
    run.heap_held_bytes.push_back(heap.held);
    if (progress) progress(label, fraction);
  });
  for (const double fraction : rss_fractions)
    run.rss_time_s.push_back(fraction * m.dive_duration_s);
  run.duration_s = m.dive_duration_s;
  run.submaps = m.submaps;
  const mapping::MapSummary s = mapping::Summarise(m);
  run.seconds = m.seconds;
  run.real_time_factor = s.real_time_factor;
  run.ate_m = s.ate_slam_m.value_or(NAN);
  *dead_reckoning_ate_m = s.ate_dead_reckoning_m.value_or(NAN);
  run.map_rms_m = DistanceToScene(m.map, caster, options.threads).rms_m;
  const std::size_t n = m.submap_seconds.size(), tenth = std::max<std::size_t>(1, n / 10);
  run.first_tenth = MedianAndP95(m.submap_seconds, 0, tenth);
  run.last_tenth = MedianAndP95(m.submap_seconds, n - tenth, n);
  run.first_tenth_stages = MeanStages(m.submap_stage_seconds, 0, tenth);
  run.last_tenth_stages = MeanStages(m.submap_stage_seconds, n - tenth, n);
  run.peak_rss_bytes = *std::max_element(run.rss_bytes.begin(), run.rss_bytes.end());
  const std::size_t last = run.rss_bytes.size(), from = last - std::max<std::size_t>(1, last / 10);
  run.rss_bytes_last_tenth = MeanFrom(run.rss_bytes, from);
  run.heap_in_use_bytes_last_tenth = MeanFrom(run.heap_in_use_bytes, from);
  run.heap_held_bytes_last_tenth = MeanFrom(run.heap_held_bytes, from);
  run.loops_accepted = s.loops_accepted;
  run.loops_false = s.loops_false.value_or(0);
  run.loops_missed = s.loops_missed.value_or(0);
  run.registrations_missed = s.registrations_missed.value_or(0);
  run.whole_solves = m.stats.whole_solves;
  run.whole_solves_beside = m.stats.whole_solves_beside;
  run.window_solves = m.stats.window_solves;
  run.loop_window_solves = m.stats.loop_window_solves;
  AddTimeSeries(m, run);
  return run;
}

LongDiveFigures BenchLongDive(double minutes, std::uint64_t seed,
                              const LongDiveBenchOptions& options,
                              const std::filesystem::path& folder, const Progress& progress) {
  LongDiveFigures f;
  char name[32];
  std::snprintf(name, sizeof name, "manifold_%gmin", minutes);
  f.name = name;
  f.seed = seed;
  const std::string scene_text = LongDiveSceneYaml(60.0 * minutes, seed);
  const scanner::sim::Scene scene =
      scanner::sim::ParseScene(scene_text, f.name, options.scenes_folder);
  const std::filesystem::path log_path = folder / (f.name + "_" + std::to_string(seed) + ".db");
  {
    const scanner::sim::Simulator simulator(scene);
    mapping::DiveSimulationOptions sim_options;
    sim_options.threads = options.threads;
    sim_options.producer = "uwscan bench slam --long";
    mapping::SimulateDive(simulator, scene_text, log_path, sim_options, [&](double fraction) {
      if (progress) progress("simulate " + f.name, fraction);
    });
  }
  const scanner::sim::RayCaster caster(scene.objects);
  f.windowed = MapLongDive(log_path, caster, true, options, "map " + f.name, progress,
                           &f.dead_reckoning_ate_m);
  if (options.whole_solves) {
    f.whole = MapLongDive(log_path, caster, false, options, "map " + f.name + " (whole solves)",
                          progress, &f.dead_reckoning_ate_m);
  }
  f.duration_s = f.windowed.duration_s;
  f.submaps = f.windowed.submaps;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
    std::error_code ignored;  // a leftover the scratch folder removes at the end anyway
    std::filesystem::remove(log_path.string() + suffix, ignored);
  }
  return f;
}

}  // namespace

void LongDiveBenchOptions::Check() const {
  const OptionChecks check("LongDiveBenchOptions");
  check.Require(!minutes.empty(), "minutes", "at least one dive length", "none");
  for (const double m : minutes) check.Positive("minutes", m);
  check.GreaterThan("threads", threads, 0);
  check.GreaterThan("seeds", seeds, 0);
  check.NonNegative("whole_solve_lag_s", whole_solve_lag_s, "s");
  check.Require(std::filesystem::is_directory(scenes_folder), "scenes_folder", "a folder",
                scenes_folder.string());
}

SubmapTimes MedianAndP95(const std::vector<double>& values, std::size_t first, std::size_t last) {
  if (last <= first) return {};
  std::vector<double> sorted(values.begin() + static_cast<std::ptrdiff_t>(first),
                             values.begin() + static_cast<std::ptrdiff_t>(last));
  std::sort(sorted.begin(), sorted.end());
  const auto rank = [&](double q) {
    return sorted[std::min(
        sorted.size() - 1,
        static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size()))) - 1)];
  };
  return {rank(0.5), rank(0.95)};
}

std::vector<LongDiveFigures> RunLongDiveBench(const LongDiveBenchOptions& options,
                                              const Progress& progress) {
  options.Check();
  ScratchFolder scratch("bench-slam-long");
  std::vector<LongDiveFigures> dives;
  for (const double minutes : options.minutes) {
    for (int k = 0; k < options.seeds; ++k) {
      const std::uint64_t seed = options.seed + static_cast<std::uint64_t>(k);
      dives.push_back(BenchLongDive(minutes, seed, options, scratch.path(), progress));
    }
  }
  return dives;
}

}  // namespace uwscan::bench
