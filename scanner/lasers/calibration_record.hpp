#pragma once

#include <string>
#include <vector>

namespace uwscan::scanner {

// What a scanner file remembers of how it was calibrated: per step, the dataset, the date, the
// residuals and every estimated parameter with its standard deviation (the `calibration:`
// section of a scanner file, data/README.md). History only: no optics are read from it.

struct ParameterEstimate {
  std::string name;  // e.g. "fx_px", "camera_viewport.distance_m"
  double value = 0.0;
  double std = 0.0;  // standard deviation from the solver's covariance; 0 when not estimated
};

struct StepRecord {
  std::string step;           // intrinsics | viewport | laser | laser_viewport | mems
  std::string dataset;        // the dataset folder it was computed from
  std::string date_utc;       // ISO 8601
  std::string residual_unit;  // "px" or "m" or "%"
  double residual_rms = 0.0;
  double residual_max = 0.0;
  int observations = 0;  // corners, points or dots used
  double seconds = 0.0;
  std::vector<ParameterEstimate> params;
};

}  // namespace uwscan::scanner
