#include "bench/scanner/stripe_benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/stripe/stripe_render.hpp"

namespace uwscan::bench {
namespace {

using Clock = std::chrono::steady_clock;

// Frames of one stripe, each with its own smooth curve crossing the middle of the image.
std::vector<scanner::StripeFrame> MakeFrames(const StripeBenchOptions& o, double sigma_px,
                                             double noise_sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<scanner::StripeFrame> frames;
  for (int f = 0; f < o.frames; ++f) {
    scanner::StripeRenderOptions render;
    render.width_px = o.width_px;
    render.height_px = o.height_px;
    render.background = o.background;
    render.noise_sigma = noise_sigma;
    render.seed = seed + 1000 + f;
    scanner::StripeSpec stripe;
    stripe.sigma_px = sigma_px;
    stripe.amplitude = o.amplitude;
    stripe.centre.offset_px = o.height_px * (0.3 + 0.4 * unit(rng));
    stripe.centre.pivot_px = 0.5 * o.width_px;
    stripe.centre.slope = 0.08 * (unit(rng) - 0.5);
    stripe.centre.wave_px = 0.05 * o.height_px * unit(rng);
    stripe.centre.period_px = o.width_px * (0.3 + unit(rng));
    stripe.centre.phase_rad = 6.283 * unit(rng);
    frames.push_back(scanner::RenderStripes(render, {stripe}));
  }
  return frames;
}

struct Accuracy {
  double rmse_px = 0.0;
  double max_err_px = 0.0;
  std::int64_t detected = 0;
  std::int64_t lines = 0;
};

Accuracy MeasureAccuracy(scanner::StripeDetector& detector,
                         const std::vector<scanner::StripeFrame>& frames) {
  Accuracy a;
  double sum2 = 0.0;
  scanner::StripeDetection detection;
  for (const scanner::StripeFrame& frame : frames) {
    detector.Detect(frame.view(), &detection);
    a.lines += detection.lines;
    for (const scanner::StripePeak& peak : detection.peaks) {
      const double e = peak.v_px - frame.truth_px[static_cast<size_t>(peak.u_px)];
      sum2 += e * e;
      a.max_err_px = std::max(a.max_err_px, std::abs(e));
      ++a.detected;
    }
  }
  a.rmse_px =
      a.detected > 0 ? std::sqrt(sum2 / a.detected) : std::numeric_limits<double>::quiet_NaN();
  return a;
}

// Frames per second of `process` over the frames in one pass at least o.min_seconds long.
template <typename Process>
double PassSpeed(const std::vector<scanner::StripeFrame>& frames, const StripeBenchOptions& o,
                 Process&& process) {
  std::int64_t done = 0;
  const Clock::time_point start = Clock::now();
  double seconds = 0.0;
  do {
    for (const scanner::StripeFrame& frame : frames) process(frame);
    done += std::ssize(frames);
    seconds = std::chrono::duration<double>(Clock::now() - start).count();
  } while (seconds < o.min_seconds);
  return done / seconds;
}

// Each column's running maximum over the rows, in row order; compiled for AVX2 too and chosen
// at run time, as the detector's own passes are.
__attribute__((target_clones("avx2", "default"))) void RunningColumnMaximum(
    const scanner::StripeImage& image, std::uint8_t* __restrict max) {
  const int width = image.width_px;
  std::fill(max, max + width, std::uint8_t{0});
  for (int v = 0; v < image.height_px; ++v) {
    const std::uint8_t* __restrict row = image.Row<std::uint8_t>(v);
    for (int u = 0; u < width; ++u) max[u] = std::max(max[u], row[u]);
  }
}

// Each row's maximum, in row order: the limit of detection along rows, compiled as the other.
__attribute__((target_clones("avx2", "default"))) std::uint64_t SumOfRowMaxima(
    const scanner::StripeImage& image) {
  std::uint64_t sum = 0;
  for (int v = 0; v < image.height_px; ++v) {
    const std::uint8_t* __restrict row = image.Row<std::uint8_t>(v);
    std::uint8_t max = 0;
    for (int u = 0; u < image.width_px; ++u) max = std::max(max, row[u]);
    sum += max;
  }
  return sum;
}

// The frame with rows and columns swapped (Mono8).
scanner::StripeFrame Transposed(const scanner::StripeFrame& frame) {
  scanner::StripeFrame t = frame;
  t.width_px = frame.height_px;
  t.height_px = frame.width_px;
  for (int v = 0; v < frame.height_px; ++v) {
    for (int u = 0; u < frame.width_px; ++u) {
      t.mono8[static_cast<size_t>(u) * t.width_px + v] =
          frame.mono8[static_cast<size_t>(v) * frame.width_px + u];
    }
  }
  return t;
}

// The limit pass: RunningColumnMaximum. The maxima go to a sink the compiler cannot drop.
class ColumnMaximumPass {
 public:
  explicit ColumnMaximumPass(int width_px) : max_(static_cast<size_t>(width_px)) {}
  void operator()(const scanner::StripeFrame& frame) {
    RunningColumnMaximum(frame.view(), max_.data());
    sink_ += max_[max_.size() / 2];
  }
  std::uint64_t sink() const { return sink_; }

 private:
  std::vector<std::uint8_t> max_;
  std::uint64_t sink_ = 0;
};

}  // namespace

void StripeBenchOptions::Check() const {
  const OptionChecks check("StripeBenchOptions");
  check.AtLeast("width_px", width_px, 16, "px");
  check.InRange("height_px", height_px, 16, 65535, Interval::kClosed, "px");
  check.AtLeast("frames", frames, 1);
  check.AtLeast("repeats", repeats, 1);
  check.AtLeast("min_seconds", min_seconds, 0.0, "s");
  check.GreaterThan("amplitude", amplitude, 0.0, "image units");
  check.AtLeast("background", background, 0.0, "image units");
  check.AtLeast("speed_noise_sigma", speed_noise_sigma, 0.0);
}

StripeBenchResult RunStripeBenchmark(const StripeBenchOptions& o, const Progress& progress) {
  o.Check();
  StripeBenchResult result;
  result.default_method = scanner::ToString(scanner::StripeDetectorOptions{}.method);
  if (progress) progress("rendering frames", 0.0);
  const std::vector<scanner::StripeFrame> speed_frames =
      MakeFrames(o, 1.5, o.speed_noise_sigma, o.seed);
  if (progress) progress("rendering frames", 0.33);
  const std::vector<scanner::StripeFrame> narrow = MakeFrames(o, 1.5, 0.0, o.seed + 1);
  if (progress) progress("rendering frames", 0.67);
  const std::vector<scanner::StripeFrame> wide = MakeFrames(o, 3.0, 0.0, o.seed + 2);
  if (progress) progress("rendering frames", 1.0);

  const std::span<const scanner::StripeMethod> methods = scanner::AllStripeMethods();
  std::vector<scanner::StripeDetector> detectors;
  for (size_t i = 0; i < methods.size(); ++i) {
    scanner::StripeDetectorOptions options;
    options.method = methods[i];
    scanner::StripeDetector& detector = detectors.emplace_back(options);
    StripeMethodFigures& f = result.methods[scanner::ToString(methods[i])];
    const Accuracy a1 = MeasureAccuracy(detector, narrow);
    const Accuracy a3 = MeasureAccuracy(detector, wide);
    f.rmse_px_sigma1_5 = a1.rmse_px;
    f.max_err_px_sigma1_5 = a1.max_err_px;
    f.rmse_px_sigma3 = a3.rmse_px;
    f.max_err_px_sigma3 = a3.max_err_px;
    f.detected_fraction = static_cast<double>(a1.detected + a3.detected) / (a1.lines + a3.lines);
  }
  // The methods and the limit run in turn within each pass and each keeps its fastest: a
  // neighbour's load on this shared machine then slows them alike, where timing the limit
  // once, after the methods, let a quiet or a disturbed moment stand against all of them.
  ColumnMaximumPass limit(o.width_px);
  scanner::StripeDetection detection;
  for (int pass = 0; pass < o.repeats; ++pass) {
    for (size_t i = 0; i < methods.size(); ++i) {
      StripeMethodFigures& f = result.methods[scanner::ToString(methods[i])];
      f.frames_per_s = std::max(f.frames_per_s, PassSpeed(speed_frames, o, [&](const auto& frame) {
                                  detectors[i].Detect(frame.view(), &detection);
                                }));
    }
    result.limit_frames_per_s =
        std::max(result.limit_frames_per_s, PassSpeed(speed_frames, o, limit));
    if (progress) progress("timing", (pass + 1.0) / o.repeats);
  }
  // Along rows, after the columns: the transposed frames would take the cache the column passes
  // read from (the two sets, 36 MB, exceed the 32 MB third-level cache).
  std::vector<scanner::StripeFrame> row_frames;
  for (const scanner::StripeFrame& frame : speed_frames) row_frames.push_back(Transposed(frame));
  scanner::StripeDetectorOptions along_rows;
  along_rows.axis = scanner::StripeAxis::kRows;
  scanner::StripeDetector rows_detector(along_rows);
  std::uint64_t row_sink = 0;
  for (int pass = 0; pass < o.repeats; ++pass) {
    result.rows.frames_per_s =
        std::max(result.rows.frames_per_s, PassSpeed(row_frames, o, [&](const auto& frame) {
                   rows_detector.Detect(frame.view(), &detection);
                 }));
    result.rows.limit_frames_per_s =
        std::max(result.rows.limit_frames_per_s, PassSpeed(row_frames, o, [&](const auto& frame) {
                   row_sink += SumOfRowMaxima(frame.view());
                 }));
  }
  if (limit.sink() == 0 || row_sink == 0) {
    throw Error("bench stripe: the limit pass saw only black frames");
  }
  result.rows.fraction_of_limit = result.rows.frames_per_s / result.rows.limit_frames_per_s;
  for (auto& [name, f] : result.methods)
    f.fraction_of_limit = f.frames_per_s / result.limit_frames_per_s;
  return result;
}

}  // namespace uwscan::bench
