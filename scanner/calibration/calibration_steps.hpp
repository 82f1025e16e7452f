#pragma once

#include <functional>
#include <string>
#include <vector>

#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/calibration/calibration_file.hpp"

namespace uwscan::scanner::calibration {

// What a user may ask the viewport steps to estimate beyond their defaults (normal and
// distance): the thickness (weakly observable, held at the measured value unless asked) and,
// for the camera viewport, the refractive indices.
struct CalibrationStepOptions {
  bool refine_thickness = false;
  bool refine_water_index = false;  // camera viewport only
  bool refine_glass_index = false;  // camera viewport only
};

struct CalibrationStepOutcome {
  Scanner scanner;  // the scanner with this step's values and record
  StepRecord record;
  std::vector<std::string> summary;  // a few lines for the user (the app prints them)
};

// Runs one step on a dataset: extracts the observations from its images (pattern corners,
// board poses, stripe peaks, dots), estimates the step's parameters starting from
// `initial` (CAD values, or the output of the earlier steps; `initial_source` names it in
// messages) and returns the updated scanner with the step's record. Throws uwscan::Error naming the
// image or the problem: a dataset of another step, no pattern found in any image, too few usable
// views.
CalibrationStepOutcome RunCalibrationStep(const std::string& step,
                                          const CalibrationDataset& dataset, const Scanner& initial,
                                          const std::string& initial_source,
                                          const std::function<void(double)>& progress = {},
                                          const CalibrationStepOptions& options = {});

}  // namespace uwscan::scanner::calibration
