#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/progress.hpp"

namespace uwscan::bench {

// Every calibration step on simulated datasets with known truth (data/scenes/calib_*.yaml:
// realistic image noise, CAD starting values a few millimetres and degrees off), the galvo
// steps chained as a user runs them (intrinsics -> viewport -> laser -> laser_viewport), then
// the seed's gauge experiment triangulated with the estimated calibration and with the true
// one.
struct CalibrationBenchOptions {
  std::filesystem::path data_dir = "data";  // holds scenes/calib_*.yaml and scanners/
  int gauge_positions = 29;
  std::uint64_t seed = 1;
  int threads = 0;
  void Check() const;
};

struct ParameterFigure {
  std::string name;
  double truth = 0.0;  // NaN when the parameter has no true counterpart
  double estimated = 0.0;
  double std = 0.0;
};

struct StepFigures {
  std::string step;
  std::vector<ParameterFigure> params;
  double residual_rms = 0.0;
  std::string residual_unit;
  double seconds = 0.0;          // the calibration itself (dataset simulation excluded)
  double dataset_seconds = 0.0;  // simulating and writing the dataset
};

struct CalibrationBenchResult {
  std::vector<StepFigures> steps;
  double gauges_true_calibration_mean_err_m = 0.0;
  double gauges_estimated_calibration_mean_err_m = 0.0;
  int gauges = 0;
  double seconds = 0.0;
};

CalibrationBenchResult RunCalibrationBenchmark(const CalibrationBenchOptions& options,
                                               const Progress& progress = {});

}  // namespace uwscan::bench
