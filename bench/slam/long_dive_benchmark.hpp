#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/progress.hpp"
#include "mapping/slam/mapper.hpp"

namespace uwscan::bench {

// Mapping cost against dive length (issue 52): dives over the manifold field of
// long_dive_scene.hpp, each simulated once into a log, then mapped with the windowed solves of
// today's mapper and, beside them, with whole-graph solves throughout (the mapper before
// windows), in one run.
struct LongDiveBenchOptions {
  std::vector<double> minutes = {4.0, 15.0, 30.0};  // dive lengths, each > 0
  std::filesystem::path scenes_folder;  // the data folder's scenes/ (the scanner file is there)
  std::uint64_t seed = 41;              // draws the navigation's drift and the peaks' noise
  int seeds = 1;  // dives per length, > 0: seed, seed + 1, ... (one seed's drift is one draw)
  int threads = 2;
  bool whole_solves = true;  // also map each dive with whole-graph solves
  // MapperOptions::whole_solve_lag_s of the windowed mapping (seconds, >= 0).
  double whole_solve_lag_s = mapping::MapperOptions{}.whole_solve_lag_s;
  std::filesystem::path table_cache;
  void Check() const;
};

// Median and 95th percentile of the time per submap over a stretch of the dive.
struct SubmapTimes {
  double median_s = 0.0;
  double p95_s = 0.0;
};

struct LongDiveRun {
  double duration_s = 0.0;  // of the dive, its first frame to its last
  int submaps = 0;
  double seconds = 0.0;  // mapping, reading the log included
  double real_time_factor = 0.0;
  double ate_m = 0.0;
  double map_rms_m = 0.0;  // distance of the map's points to the true surfaces
  SubmapTimes first_tenth, last_tenth;
  // The mean time per submap by stage over the same stretches: where the growth is.
  mapping::MapperStageSeconds first_tenth_stages, last_tenth_stages;
  std::int64_t rss_bytes_at_start = 0;            // the process's resident memory before mapping
  std::int64_t peak_rss_bytes = 0;                // and while mapping, at most
  std::int64_t rss_bytes_last_tenth = 0;          // its mean over the last tenth of the dive
  std::int64_t heap_in_use_bytes_last_tenth = 0;  // the same for the heap (CurrentHeapBytes)
  std::int64_t heap_held_bytes_last_tenth = 0;
  int loops_accepted = 0;
  int loops_false = 0;   // of those, the ones the truth puts off (MapSummary::loops_false)
  int loops_missed = 0;  // right loops the chi-square turned away (MapSummary::loops_missed)
  // Right consecutive registrations it turned away (MapSummary::registrations_missed).
  int registrations_missed = 0;
  int whole_solves = 0, whole_solves_beside = 0, window_solves = 0;
  int loop_window_solves = 0;  // window solves freed back to a correcting loop's older end
  // Over the dive (seconds of dive time): the mean time per submap in each of about 60 stretches,
  // and the resident memory sampled as the frames went by.
  std::vector<double> submap_time_s, submap_seconds;
  std::vector<double> rss_time_s;
  std::vector<std::int64_t> rss_bytes;
  // At the same times, the heap the program holds and what the allocator holds for it
  // (CurrentHeapBytes): whether resident memory grows with what the mapper keeps or with the
  // allocator's free space.
  std::vector<std::int64_t> heap_in_use_bytes, heap_held_bytes;
};

struct LongDiveFigures {
  std::string name;
  std::uint64_t seed = 0;
  double duration_s = 0.0;
  int submaps = 0;
  double dead_reckoning_ate_m = 0.0;
  LongDiveRun windowed;
  std::optional<LongDiveRun> whole;
};

std::vector<LongDiveFigures> RunLongDiveBench(const LongDiveBenchOptions& options,
                                              const Progress& progress = {});

// The median and the 95th percentile (nearest rank) of `values` from index `first` to `last`
// (exclusive); zeros when the range is empty.
SubmapTimes MedianAndP95(const std::vector<double>& values, std::size_t first, std::size_t last);

}  // namespace uwscan::bench
