#include "scanner/stripe/stripe_detector.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <vector>

#include "scanner/common/option_checks.hpp"
#include "scanner/stripe/column_scan.hpp"
#include "scanner/stripe/row_scan.hpp"
#include "scanner/stripe/steger_batch.hpp"
#include "scanner/stripe/zero_crossing.hpp"

namespace uwscan::scanner {
namespace {

using stripe_detail::ColumnScratch;
using stripe_detail::kCrossingReach;
using stripe_detail::SecondPeakCut;
using stripe_detail::StegerBatch;
using stripe_detail::ZeroCrossingNear;

constexpr std::array<StripeMethod, 6> kAllMethods = {
    StripeMethod::kMaximum,  StripeMethod::kCentreOfMass, StripeMethod::kGaussian,
    StripeMethod::kParabola, StripeMethod::kBlaisRioux,   StripeMethod::kSteger};

// Lines handled together: a group of columns whose rows around the stripe are read row by row
// (ScanGroup), and the lines whose refinement waits for a StegerBatch.
constexpr int kBatchLines = StegerBatch::kLines;
static_assert(kBatchLines == stripe_detail::kGroupColumns);

// What the refinement of one line needs from the options, so that the per-line code sees only
// scalars and the Steger kernel.
struct RefineParams {
  StripeMethod method;
  int half_window;                    // window_px / 2
  int support;                        // pixels needed each side of the brightest one
  std::span<const double> steger_d1;  // k = -R..R
};

// The lowest of the samples p(k), k in [-left, right], and `top`.
template <typename Profile>
double LowestIn(const Profile& p, int left, int right, double top) {
  double low = top;
  for (int k = -left; k <= right; ++k) low = std::min(low, p(k));
  return low;
}

// The centre of a flat top (saturated, or a run of equal samples 0..run_end): the midpoint of
// its half-level crossings, searched within k in [-left, right]; std::nullopt when they are not
// found there.
template <typename Profile>
std::optional<double> FlatTopCentre(const Profile& p, int run_end, int left, int right) {
  const double top = p(0);
  const double low = LowestIn(p, left, right, top);
  const double level = 0.5 * (top + low);
  if (!(level < top)) return std::nullopt;
  int a = -1;
  while (a >= -left && p(a) > level) --a;
  int b = run_end + 1;
  while (b <= right && p(b) > level) ++b;
  if (a < -left || b > right) return std::nullopt;
  const double left_x = a + (level - p(a)) / (p(a + 1) - p(a));
  const double right_x = b - 1 + (p(b - 1) - level) / (p(b - 1) - p(b));
  return 0.5 * (left_x + right_x);
}

// Centre of mass of the samples above the lowest within h of the peak.
template <typename Profile>
double CentreOfMassOffset(const Profile& p, int h) {
  const double low = LowestIn(p, h, h, p(0));
  double sum_w = 0.0, sum_kw = 0.0;
  for (int k = -h; k <= h; ++k) {
    const double w = p(k) - low;
    sum_w += w;
    sum_kw += k * w;
  }
  return sum_w > 0.0 ? sum_kw / sum_w : 0.0;
}

// The vertex of the parabola through the logarithms of the three samples at the peak, above the
// lowest within h of it.
template <typename Profile>
std::optional<double> GaussianOffset(const Profile& p, int h) {
  const double top = p(0);
  const double low = LowestIn(p, h, h, top);
  // Half an intensity level keeps the logarithm finite where a neighbour is at background.
  const double a = std::log(std::max(p(-1) - low, 0.5));
  const double b = std::log(std::max(top - low, 0.5));
  const double c = std::log(std::max(p(1) - low, 0.5));
  const double curvature = a - 2.0 * b + c;
  if (!(curvature < 0.0)) return std::nullopt;
  return 0.5 * (a - c) / curvature;
}

// The vertex of the parabola through the three samples at the peak.
template <typename Profile>
std::optional<double> ParabolaOffset(const Profile& p) {
  const double top = p(0);
  const double curvature = p(-1) - 2.0 * top + p(1);
  if (!(curvature < 0.0)) return std::nullopt;
  return 0.5 * (p(-1) - p(1)) / curvature;
}

template <typename Profile>
std::optional<double> BlaisRiouxOffset(const Profile& p) {
  // Blais & Rioux's filter g(k) = I(k-2) + I(k-1) - I(k+1) - I(k+2), negated here so that,
  // like a slope, it is positive on the rising side; the centre is its zero crossing.
  const auto g = [&](int k) { return p(k + 1) + p(k + 2) - p(k - 1) - p(k - 2); };
  return ZeroCrossingNear(g);
}

template <typename Profile>
std::optional<double> StegerOffset(const Profile& p, std::span<const double> steger_d1) {
  // First derivative of the Gaussian-smoothed profile: positive rising, negative after.
  const int r = static_cast<int>(steger_d1.size() / 2);
  const auto d = [&](int k) {
    double sum = 0.0;
    for (int j = -r; j <= r; ++j) sum += p(k + j) * steger_d1[j + r];
    return sum;
  };
  return ZeroCrossingNear(d);
}

// The sub-pixel offset of a peak that is not flat by rp.method, its samples p(k) reaching h
// each side.
template <typename Profile>
std::optional<double> PeakOffset(const RefineParams& rp, const Profile& p, int h) {
  switch (rp.method) {
    case StripeMethod::kMaximum:
      return 0.0;
    case StripeMethod::kCentreOfMass:
      return CentreOfMassOffset(p, h);
    case StripeMethod::kGaussian:
      return GaussianOffset(p, h);
    case StripeMethod::kParabola:
      return ParabolaOffset(p);
    case StripeMethod::kBlaisRioux:
      return BlaisRiouxOffset(p);
    case StripeMethod::kSteger:
      return StegerOffset(p, rp.steger_d1);
  }
  return std::nullopt;
}

// The refinement of one line. at(i) is the line's sample i in [0, n); i0 its brightest sample
// (the first of equal maxima). Returns the sub-pixel offset from i0, or std::nullopt.
template <typename Get>
std::optional<double> RefineLine(const RefineParams& rp, const Get& at, int n, int i0,
                                 double saturation) {
  const auto p = [&](int k) { return at(i0 + k); };
  const double top = p(0);
  const int available_left = i0;
  const int available_right = n - 1 - i0;

  // The run of samples equal to the top (i0 is its first).
  int run_end = 0;
  while (run_end < available_right && p(run_end + 1) == top) ++run_end;
  if (rp.method == StripeMethod::kMaximum) return 0.5 * run_end;

  if (top >= saturation || run_end >= 2) {
    // A flat top: its half-level crossings are searched within half_window of the run.
    return FlatTopCentre(p, run_end, std::min(available_left, rp.half_window),
                         std::min(available_right, run_end + rp.half_window));
  }
  if (available_left < rp.support || available_right < rp.support) {
    // Only the centre of mass makes do with less support, as long as there is a sample each side.
    if (rp.method != StripeMethod::kCentreOfMass || available_left < 1 || available_right < 1) {
      return std::nullopt;
    }
  }
  return PeakOffset(rp, p, std::min({rp.half_window, available_left, available_right}));
}

// One line of a batch: what the scan found and what became of it.
struct BatchLine {
  enum class Kind : std::uint8_t { kBelowThreshold, kMultiplePeaks, kRefined, kBatched };
  Kind kind = Kind::kBelowThreshold;
  int i0 = 0;        // its brightest sample
  double top = 0.0;  // and that sample's value
  // kRefined: RefineLine's answer (refined: whether there is one); kBatched: its place in the
  // StegerBatch.
  bool refined = false;
  double offset = 0.0;
  int slot = 0;
};

// Refines `line` now, or adds it to `batch` (when given) if its refinement is Steger's slopes:
// the same answer RefineLine gives, later.
// The line's samples are first[i * step], i in [0, n).
template <typename Pixel>
void RefineOrBatch(const RefineParams& rp, const Pixel* first, std::ptrdiff_t step, int n,
                   double saturation, StegerBatch* batch, BatchLine* line) {
  const int i0 = line->i0;
  const Pixel* centre = first + i0 * step;
  const Pixel top = *centre;
  if (batch != nullptr && top < saturation && i0 >= batch->support() &&
      n - 1 - i0 >= batch->support() && !(centre[step] == top && centre[2 * step] == top)) {
    line->kind = BatchLine::Kind::kBatched;
    line->slot = batch->Add(centre, step);
    return;
  }
  line->kind = BatchLine::Kind::kRefined;
  const auto at = [first, step](int i) { return static_cast<double>(first[i * step]); };
  const std::optional<double> offset = RefineLine(rp, at, n, i0, saturation);
  line->refined = offset.has_value();
  line->offset = offset.value_or(0.0);
}

// Whether a line of a computed batch carries a peak, and if so its offset; the reason counted
// when it does not.
bool CountedOffset(const BatchLine& line, const StegerBatch& batch, StripeDetection* result,
                   double* offset) {
  bool refined = false;
  switch (line.kind) {
    case BatchLine::Kind::kBelowThreshold:
      ++result->below_threshold;
      return false;
    case BatchLine::Kind::kMultiplePeaks:
      ++result->multiple_peaks;
      return false;
    case BatchLine::Kind::kRefined:
      refined = line.refined;
      *offset = line.offset;
      break;
    case BatchLine::Kind::kBatched:
      refined = batch.Refined(line.slot, offset);
      break;
  }
  if (!refined) ++result->unrefined;
  return refined;
}

}  // namespace

struct StripeDetector::Scratch {
  ColumnScratch<std::uint8_t> mono8;
  ColumnScratch<std::uint16_t> mono16;
  std::optional<StegerBatch> steger_batch;  // built with the detector's kernel
  std::array<BatchLine, kBatchLines> lines;
  std::array<stripe_detail::RowFound, kBatchLines> rows;
  StegerBatch& steger() { return *steger_batch; }
};

StripeDetector::~StripeDetector() = default;
StripeDetector::StripeDetector(StripeDetector&&) noexcept = default;
StripeDetector& StripeDetector::operator=(StripeDetector&&) noexcept = default;

const char* ToString(StripeMethod method) {
  switch (method) {
    case StripeMethod::kMaximum:
      return "maximum";
    case StripeMethod::kCentreOfMass:
      return "centre_of_mass";
    case StripeMethod::kGaussian:
      return "gaussian";
    case StripeMethod::kParabola:
      return "parabola";
    case StripeMethod::kBlaisRioux:
      return "blais_rioux";
    case StripeMethod::kSteger:
      return "steger";
  }
  return "unknown";
}

std::optional<StripeMethod> StripeMethodFromString(std::string_view name) {
  for (StripeMethod m : kAllMethods) {
    if (name == ToString(m)) return m;
  }
  return std::nullopt;
}

std::span<const StripeMethod> AllStripeMethods() { return kAllMethods; }

void StripeDetectorOptions::Check() const {
  const OptionChecks check("StripeDetectorOptions");
  if (static_cast<int>(method) > static_cast<int>(StripeMethod::kSteger)) {
    std::string names;
    for (StripeMethod m : kAllMethods)
      names += (names.empty() ? "" : ", ") + std::string(ToString(m));
    check.Fail("method", "one of " + names, std::to_string(static_cast<int>(method)));
  }
  check.Require(axis == StripeAxis::kColumns || axis == StripeAxis::kRows, "axis",
                "columns or rows", static_cast<int>(axis));
  check.InRange("threshold", threshold, 1, 65535, Interval::kClosed, "image units");
  check.Require(window_px >= 3 && window_px <= 255 && window_px % 2 != 0, "window_px",
                "an odd width in [3, 255] px", window_px);
  check.InRange("max_second_peak_ratio", max_second_peak_ratio, 0.0, 1.0, Interval::kOpenLow,
                "(1 disables multiple-peak rejection)");
  check.AtLeast("min_separation_px", min_separation_px, 1, "px");
  check.InRange("steger_sigma_px", steger_sigma_px, 0.5, 10.0, Interval::kClosed, "px");
}

StripeDetector::StripeDetector(const StripeDetectorOptions& options)
    : options_(options), scratch_(std::make_unique<Scratch>()) {
  options_.Check();
  // Steger's kernel integrates the Gaussian derivative over each pixel:
  // d1[j] = G(j - 1/2) - G(j + 1/2), so that sum_j I(k + j) d1[j] is the smoothed slope at k.
  const double s = options_.steger_sigma_px;
  steger_radius_ = static_cast<int>(std::ceil(3.0 * s));
  const auto gauss = [s](double x) {
    return std::exp(-0.5 * x * x / (s * s)) / (s * 2.5066282746310002);
  };
  steger_d1_.resize(2 * steger_radius_ + 1);
  for (int j = -steger_radius_; j <= steger_radius_; ++j) {
    steger_d1_[j + steger_radius_] = gauss(j - 0.5) - gauss(j + 0.5);
  }
  scratch_->steger_batch.emplace(steger_d1_);
  switch (options_.method) {
    case StripeMethod::kMaximum:
      support_radius_ = 0;
      break;
    case StripeMethod::kCentreOfMass:
    case StripeMethod::kGaussian:
    case StripeMethod::kParabola:
      support_radius_ = 1;
      break;
    case StripeMethod::kBlaisRioux:
      support_radius_ = 2 + kCrossingReach;
      break;
    case StripeMethod::kSteger:
      support_radius_ = steger_radius_ + kCrossingReach;
      break;
  }
}

std::optional<double> StripeDetector::RefinePeak(std::span<const double> profile, int peak_index,
                                                 double saturation) const {
  if (peak_index < 0 || peak_index >= std::ssize(profile)) {
    throw Error("stripe detector: peak_index " + std::to_string(peak_index) +
                " outside the profile of " + std::to_string(profile.size()) + " samples");
  }
  const RefineParams rp{options_.method, options_.window_px / 2, support_radius_, steger_d1_};
  return RefineLine(
      rp, [&](int i) { return profile[i]; }, static_cast<int>(profile.size()), peak_index,
      saturation);
}

template <typename Pixel>
void StripeDetector::DetectColumns(const StripeImage& image, StripeDetection* result) {
  const int width = image.width_px;
  const int height = image.height_px;
  ColumnScratch<Pixel>* scratch;
  if constexpr (sizeof(Pixel) == 1) {
    scratch = &scratch_->mono8;
  } else {
    scratch = &scratch_->mono16;
  }
  scratch->Resize(width, (height + stripe_detail::kBlockRows - 1) / stripe_detail::kBlockRows);
  const bool reject_multiple = options_.max_second_peak_ratio < 1.0;
  stripe_detail::ScanColumns(image, reject_multiple, options_.threshold,
                             options_.max_second_peak_ratio, *scratch);
  const std::uint16_t* arg = scratch->arg.data();

  const RefineParams rp{options_.method, options_.window_px / 2, support_radius_, steger_d1_};
  const double saturation = MaxPixelValue(image.format);
  const Pixel* __restrict max = scratch->max.data();
  const std::ptrdiff_t step = image.stride_bytes / static_cast<std::ptrdiff_t>(sizeof(Pixel));
  StegerBatch* batch = options_.method == StripeMethod::kSteger ? &scratch_->steger() : nullptr;
  std::array<BatchLine, kBatchLines>& lines = scratch_->lines;
  for (int begin = 0; begin < width; begin += kBatchLines) {
    const int end = std::min(width, begin + kBatchLines);
    if (batch != nullptr) batch->Clear();
    stripe_detail::ScanGroup(image, begin, end, reject_multiple, options_.min_separation_px,
                             *scratch);
    for (int u = begin; u < end; ++u) {
      BatchLine& line = lines[static_cast<std::size_t>(u - begin)];
      line.i0 = arg[u];
      line.top = max[u];
      if (line.top < options_.threshold) {
        line.kind = BatchLine::Kind::kBelowThreshold;
      } else if (reject_multiple && scratch->group_reject[static_cast<std::size_t>(u - begin)]) {
        line.kind = BatchLine::Kind::kMultiplePeaks;
      } else {
        RefineOrBatch(rp, image.Row<Pixel>(0) + u, step, height, saturation, batch, &line);
      }
    }
    if (batch != nullptr) batch->Compute();
    for (int u = begin; u < end; ++u) {
      const BatchLine& line = lines[static_cast<std::size_t>(u - begin)];
      double offset = 0.0;
      if (CountedOffset(line, scratch_->steger(), result, &offset)) {
        result->peaks.push_back({static_cast<double>(u), line.i0 + offset, line.top});
      }
    }
  }
}

template <typename Pixel>
void StripeDetector::DetectRows(const StripeImage& image, StripeDetection* result) {
  const int width = image.width_px;
  const int height = image.height_px;
  const RefineParams rp{options_.method, options_.window_px / 2, support_radius_, steger_d1_};
  const double saturation = MaxPixelValue(image.format);
  StegerBatch* batch = options_.method == StripeMethod::kSteger ? &scratch_->steger() : nullptr;
  std::array<BatchLine, kBatchLines>& lines = scratch_->lines;
  std::array<stripe_detail::RowFound, kBatchLines>& rows = scratch_->rows;
  for (int begin = 0; begin < height; begin += kBatchLines) {
    const int end = std::min(height, begin + kBatchLines);
    if (batch != nullptr) batch->Clear();
    stripe_detail::ScanRows(image, begin, end, options_.min_separation_px, options_.threshold,
                            options_.max_second_peak_ratio, rows.data());
    for (int v = begin; v < end; ++v) {
      const stripe_detail::RowFound& found = rows[static_cast<std::size_t>(v - begin)];
      BatchLine& line = lines[static_cast<std::size_t>(v - begin)];
      line.i0 = found.u0;
      line.top = found.top;
      if (found.top < options_.threshold) {
        line.kind = BatchLine::Kind::kBelowThreshold;
      } else if (found.second_peak) {
        line.kind = BatchLine::Kind::kMultiplePeaks;
      } else {
        RefineOrBatch(rp, image.Row<Pixel>(v), 1, width, saturation, batch, &line);
      }
    }
    if (batch != nullptr) batch->Compute();
    for (int v = begin; v < end; ++v) {
      const BatchLine& line = lines[static_cast<std::size_t>(v - begin)];
      double offset = 0.0;
      if (CountedOffset(line, scratch_->steger(), result, &offset)) {
        result->peaks.push_back({line.i0 + offset, static_cast<double>(v), line.top});
      }
    }
  }
}

void StripeDetector::Detect(const StripeImage& image, StripeDetection* result) {
  image.Check();
  const bool columns = options_.axis == StripeAxis::kColumns;
  if (columns && image.height_px > 65535) {
    throw Error("stripe detector: image of " + std::to_string(image.height_px) +
                " rows, expected at most 65535 for per-column detection");
  }
  result->peaks.clear();
  result->lines = columns ? image.width_px : image.height_px;
  result->below_threshold = result->multiple_peaks = result->unrefined = 0;
  const bool mono8 = image.format == PixelFormat::kMono8;
  if (columns) {
    mono8 ? DetectColumns<std::uint8_t>(image, result)
          : DetectColumns<std::uint16_t>(image, result);
  } else {
    mono8 ? DetectRows<std::uint8_t>(image, result) : DetectRows<std::uint16_t>(image, result);
  }
}

StripeDetection StripeDetector::Detect(const StripeImage& image) {
  StripeDetection result;
  Detect(image, &result);
  return result;
}

}  // namespace uwscan::scanner
