#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "bench/progress.hpp"
#include "scanner/stripe/stripe_detector.hpp"

namespace uwscan::bench {

// Speed and accuracy of every stripe detection method. Speed: frames per second on one core
// over `frames` distinct 2048x1088 Mono8 frames of a mildly noisy stripe (sigma 1.5 px),
// the fastest of `repeats` passes, the methods and the limit in turn within each pass. Accuracy:
// RMSE of the detected centre against the renderer's exact centre over every column of `frames`
// clean Mono8 frames per stripe width (sigma 1.5 and 3 px), each frame with a different smooth
// curve, so sub-pixel offsets are spread evenly. Every method runs with the same default
// StripeDetectorOptions except its method.
struct StripeBenchOptions {
  int width_px = 2048;
  int height_px = 1088;
  int frames = 8;                  // distinct frames per measurement, >= 1
  double min_seconds = 0.1;        // each method's share of a pass runs at least this long, s
  int repeats = 10;                // speed passes; each method's fastest is reported, >= 1
  double amplitude = 200.0;        // stripe height over the background, image units
  double background = 10.0;        // image units
  double speed_noise_sigma = 2.0;  // noise of the speed frames, image units
  std::uint64_t seed = 1;

  void Check() const;
};

struct StripeMethodFigures {
  double frames_per_s = 0.0;
  double rmse_px_sigma1_5 = 0.0;
  double rmse_px_sigma3 = 0.0;
  double max_err_px_sigma1_5 = 0.0;
  double max_err_px_sigma3 = 0.0;
  double detected_fraction = 0.0;  // columns with a peak over all accuracy frames
  double fraction_of_limit = 0.0;  // frames_per_s / StripeBenchResult::limit_frames_per_s
};

// The default method along rows (StripeAxis::kRows) on the speed frames transposed (1088 wide,
// 2048 tall: one stripe crossing every row), beside its own limit: one pass in row order keeping
// each row's maximum. The two are timed in turn, in passes of their own after the columns'.
struct StripeRowsFigures {
  double frames_per_s = 0.0;
  double limit_frames_per_s = 0.0;
  double fraction_of_limit = 0.0;  // frames_per_s / limit_frames_per_s
};

struct StripeBenchResult {
  std::string default_method;  // ToString(StripeDetectorOptions{}.method)
  StripeRowsFigures rows;
  // The floor of any per-column detector, measured on the same frames in the same run: one
  // pass reading every pixel in row order (the detectors' memory order) that keeps each
  // column's running maximum, and nothing else.
  double limit_frames_per_s = 0.0;
  std::map<std::string, StripeMethodFigures> methods;  // keyed by ToString(method)
};

StripeBenchResult RunStripeBenchmark(const StripeBenchOptions& options,
                                     const Progress& progress = {});

}  // namespace uwscan::bench
