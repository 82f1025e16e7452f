#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/progress.hpp"

namespace uwscan::bench {

// What each simulation effect costs: the time per frame of a scene with every effect off, then
// with each effect alone on, then all on, in one run, so a reader sees each stage's cost and
// that an effect left off costs nothing (a row with every effect off but all their parameters
// changed must match the all-off row within noise). Frames only: building the simulator (the
// ray caster's acceleration structure, the scanner's tables) is not timed.
struct SimulationBenchOptions {
  std::filesystem::path data_dir = "data";  // scenes/default.yaml (galvo), scenes/mems_plane.yaml
  int frames = 12;  // frames timed per row, evenly spread over the sweep, >= 1
  int repeats = 3;  // passes per row; the fastest counts, >= 1
  void Check() const;
};

struct EffectCost {
  std::string scene;   // "galvo" or "mems"
  std::string effect;  // "none", an effect's name, "off_with_parameters", or "all"
  double ms_per_frame = 0.0;
  double ratio_to_none = 0.0;  // ms_per_frame / the scene's "none" row
  std::int64_t peaks = 0;      // stripe peaks of the timed frames (what the stage produced)
};

struct SimulationBenchResult {
  int frames = 0;
  std::vector<EffectCost> rows;  // per scene: none first, then effects, off_with_parameters, all
};

SimulationBenchResult RunSimulationBenchmark(const SimulationBenchOptions& options,
                                             const Progress& progress = {});

}  // namespace uwscan::bench
