#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "scanner/sim/simulator.hpp"

namespace uwscan::mapping {

struct DiveSimulationOptions {
  bool store_images = false;  // keep rendered frames in the log (only when image stages are on)
  int threads = 0;            // frames simulated in parallel; 0 = OpenMP's default
  double navigation_rate_hz = 20.0;
  std::string producer = "uwscan";
  void Check() const;
};

struct DiveSimulationSummary {
  std::int64_t frames = 0;
  std::int64_t peaks = 0;
  std::int64_t navigation_records = 0;
  bool images_stored = false;
  double seconds = 0.0;
};

// Simulates every frame of `simulator` and writes a new dive log at `log_path`: the header
// (effective scanner configuration, scan pattern, scene text), the navigation, then frame after
// frame, each committed with its ground truth. Frames are simulated in parallel blocks but
// written in order, so the log is the same whatever the thread count. A failure midway leaves
// a readable log of the frames written so far.
DiveSimulationSummary SimulateDive(const scanner::sim::Simulator& simulator,
                                   const std::string& scene_yaml,
                                   const std::filesystem::path& log_path,
                                   const DiveSimulationOptions& options,
                                   const std::function<void(double)>& progress = {});

}  // namespace uwscan::mapping
