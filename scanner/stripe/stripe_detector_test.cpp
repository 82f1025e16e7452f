#include "scanner/stripe/stripe_detector.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/stripe/stripe_render.hpp"

namespace uwscan::scanner {
namespace {

struct Errors {
  double rmse_px = 0.0;
  double max_px = 0.0;
  int peaks = 0;
};

// Compares peaks with the frame's exact centres (axis-aware).
Errors Compare(const StripeDetection& detection, const StripeFrame& frame, StripeAxis axis) {
  Errors e;
  double sum2 = 0.0;
  for (const StripePeak& p : detection.peaks) {
    const bool columns = axis == StripeAxis::kColumns;
    const int line = static_cast<int>(columns ? p.u_px : p.v_px);
    const double error = (columns ? p.v_px : p.u_px) - frame.truth_px.at(line);
    sum2 += error * error;
    e.max_px = std::max(e.max_px, std::abs(error));
    ++e.peaks;
  }
  e.rmse_px = e.peaks > 0 ? std::sqrt(sum2 / e.peaks) : 0.0;
  return e;
}

StripeRenderOptions Small(StripeAxis axis, PixelFormat format) {
  StripeRenderOptions o;
  const bool columns = axis == StripeAxis::kColumns;
  o.width_px = columns ? 600 : 90;
  o.height_px = columns ? 90 : 600;
  o.axis = axis;
  o.format = format;
  o.background = format == PixelFormat::kMono8 ? 10.0 : 600.0;
  return o;
}

StripeSpec Stripe(double sigma_px, double amplitude, double offset_px = 44.3) {
  StripeSpec s;
  s.sigma_px = sigma_px;
  s.amplitude = amplitude;
  s.centre.offset_px = offset_px;
  s.centre.slope = 0.0137;
  s.centre.pivot_px = 300.0;
  s.centre.wave_px = 2.5;
  s.centre.period_px = 517.0;
  return s;
}

StripeDetectorOptions With(StripeMethod method, StripeAxis axis = StripeAxis::kColumns) {
  StripeDetectorOptions o;
  o.method = method;
  o.axis = axis;
  return o;
}

// ---------------------------------------------------------------------------------------------
// Every method against ground truth: clean stripes, both widths, both formats, both axes.

struct Case {
  StripeMethod method;
  StripeAxis axis;
  PixelFormat format;
  double sigma_px;
};

std::string CaseName(const testing::TestParamInfo<Case>& info) {
  const Case& c = info.param;
  return std::string(ToString(c.method)) + (c.axis == StripeAxis::kColumns ? "_columns" : "_rows") +
         (c.format == PixelFormat::kMono8 ? "_mono8" : "_mono16") + "_sigma" +
         (c.sigma_px < 2.0 ? "1_5" : "3");
}

std::vector<Case> AllCases() {
  std::vector<Case> cases;
  for (StripeMethod m : AllStripeMethods()) {
    for (StripeAxis a : {StripeAxis::kColumns, StripeAxis::kRows}) {
      for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
        for (double s : {1.5, 3.0}) cases.push_back({m, a, f, s});
      }
    }
  }
  return cases;
}

class CleanStripe : public testing::TestWithParam<Case> {};

TEST_P(CleanStripe, MatchesGroundTruth) {
  const Case& c = GetParam();
  const double amplitude = c.format == PixelFormat::kMono8 ? 200.0 : 40000.0;
  const StripeFrame frame = RenderStripes(Small(c.axis, c.format), {Stripe(c.sigma_px, amplitude)});
  StripeDetector detector(With(c.method, c.axis));
  const StripeDetection d = detector.Detect(frame.view());
  ASSERT_EQ(d.lines, static_cast<int>(frame.truth_px.size()));
  ASSERT_EQ(std::ssize(d.peaks), d.lines) << "every line carries the stripe";
  const Errors e = Compare(d, frame, c.axis);
  if (c.method == StripeMethod::kMaximum) {
    EXPECT_LE(e.max_px, 0.5 + 1e-9);
  } else {
    EXPECT_LE(e.rmse_px, 0.05);
    EXPECT_LE(e.max_px, 0.1);
  }
  // Detector order: line by line, increasing.
  for (size_t i = 1; i < d.peaks.size(); ++i) {
    const bool columns = c.axis == StripeAxis::kColumns;
    EXPECT_LT(columns ? d.peaks[i - 1].u_px : d.peaks[i - 1].v_px,
              columns ? d.peaks[i].u_px : d.peaks[i].v_px);
  }
}

INSTANTIATE_TEST_SUITE_P(AllMethods, CleanStripe, testing::ValuesIn(AllCases()), CaseName);

// ---------------------------------------------------------------------------------------------

TEST(StripeDetector, NoiseRobustness) {
  StripeRenderOptions o = Small(StripeAxis::kColumns, PixelFormat::kMono8);
  o.width_px = 2000;
  o.noise_sigma = 3.0;
  o.seed = 7;
  const StripeFrame frame = RenderStripes(o, {Stripe(1.5, 200.0)});
  for (StripeMethod m : AllStripeMethods()) {
    if (m == StripeMethod::kMaximum) continue;
    StripeDetector detector(With(m));
    const StripeDetection d = detector.Detect(frame.view());
    EXPECT_EQ(std::ssize(d.peaks), o.width_px) << ToString(m);
    const Errors e = Compare(d, frame, StripeAxis::kColumns);
    EXPECT_LE(e.rmse_px, 0.06) << ToString(m);
    EXPECT_LE(e.max_px, 0.3) << ToString(m);
  }
}

TEST(StripeDetector, ThresholdLeavesDarkLinesEmpty) {
  const StripeRenderOptions o = Small(StripeAxis::kColumns, PixelFormat::kMono8);
  // Brightest pixel ~ 10 + 20 = 30 < 40: no line carries a peak.
  const StripeFrame dim = RenderStripes(o, {Stripe(1.5, 20.0)});
  for (StripeMethod m : AllStripeMethods()) {
    StripeDetector detector(With(m));
    const StripeDetection d = detector.Detect(dim.view());
    EXPECT_TRUE(d.peaks.empty()) << ToString(m);
    EXPECT_EQ(d.below_threshold, o.width_px);
  }
  // Half the columns dark: only the lit ones carry a peak.
  StripeFrame half = RenderStripes(o, {Stripe(1.5, 200.0)});
  for (int v = 0; v < o.height_px; ++v) {
    std::fill_n(half.mono8.begin() + v * o.width_px, o.width_px / 2, std::uint8_t{10});
  }
  StripeDetector detector;
  const StripeDetection d = detector.Detect(half.view());
  EXPECT_EQ(d.below_threshold, o.width_px / 2);
  ASSERT_EQ(std::ssize(d.peaks), o.width_px - o.width_px / 2);
  EXPECT_EQ(d.peaks.front().u_px, o.width_px / 2);
}

TEST(StripeDetector, RejectsLinesWithTwoPeaks) {
  const StripeRenderOptions o = Small(StripeAxis::kColumns, PixelFormat::kMono8);
  StripeSpec reflection = Stripe(1.5, 160.0, 70.6);  // 0.8 of the main stripe, 26 px away
  const StripeFrame two = RenderStripes(o, {Stripe(1.5, 200.0, 44.3), reflection});
  StripeDetector rejecting;  // default: max_second_peak_ratio 0.5
  StripeDetection d = rejecting.Detect(two.view());
  EXPECT_TRUE(d.peaks.empty());
  EXPECT_EQ(d.multiple_peaks, o.width_px);

  StripeDetectorOptions keep;
  keep.max_second_peak_ratio = 1.0;
  StripeDetector keeping(keep);
  d = keeping.Detect(two.view());
  ASSERT_EQ(std::ssize(d.peaks), o.width_px);
  EXPECT_LE(Compare(d, two, StripeAxis::kColumns).max_px, 0.1);  // the brighter one

  // A faint second stripe (0.3 of the first) is tolerated.
  reflection.amplitude = 60.0;
  const StripeFrame faint = RenderStripes(o, {Stripe(1.5, 200.0, 44.3), reflection});
  d = rejecting.Detect(faint.view());
  EXPECT_EQ(std::ssize(d.peaks), o.width_px);

  // The same along rows.
  const StripeRenderOptions r = Small(StripeAxis::kRows, PixelFormat::kMono16);
  reflection.amplitude = 32000.0;
  const StripeFrame rows = RenderStripes(r, {Stripe(1.5, 40000.0, 44.3), reflection});
  StripeDetector row_detector(With(StripeMethod::kSteger, StripeAxis::kRows));
  d = row_detector.Detect(rows.view());
  EXPECT_TRUE(d.peaks.empty());
  EXPECT_EQ(d.multiple_peaks, r.height_px);
}

TEST(StripeDetector, SaturatedStripe) {
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    const StripeRenderOptions o = Small(StripeAxis::kColumns, f);
    const double amplitude = 3.0 * MaxPixelValue(f);  // flat top several pixels wide
    const StripeFrame frame = RenderStripes(o, {Stripe(3.0, amplitude)});
    for (StripeMethod m : AllStripeMethods()) {
      StripeDetector detector(With(m));
      const StripeDetection d = detector.Detect(frame.view());
      ASSERT_EQ(std::ssize(d.peaks), o.width_px) << ToString(m);
      EXPECT_EQ(d.peaks.front().intensity, MaxPixelValue(f));
      const Errors e = Compare(d, frame, StripeAxis::kColumns);
      EXPECT_LE(e.max_px, m == StripeMethod::kMaximum ? 0.5 + 1e-9 : 0.1) << ToString(m);
    }
  }
}

TEST(StripeDetector, StripeAtTheImageBorder) {
  StripeRenderOptions o = Small(StripeAxis::kColumns, PixelFormat::kMono8);
  StripeSpec s = Stripe(1.5, 200.0);
  s.centre.slope = s.centre.wave_px = 0.0;
  for (double centre : {0.0, o.height_px - 1.0}) {
    s.centre.offset_px = centre;
    const StripeFrame frame = RenderStripes(o, {s});
    for (StripeMethod m : AllStripeMethods()) {
      StripeDetector detector(With(m));
      const StripeDetection d = detector.Detect(frame.view());
      if (m == StripeMethod::kMaximum) {
        ASSERT_EQ(std::ssize(d.peaks), o.width_px);
        EXPECT_EQ(d.peaks.front().v_px, centre);
      } else {
        // The centre cannot be bracketed: no peak, rather than a biased one.
        EXPECT_TRUE(d.peaks.empty()) << ToString(m);
        EXPECT_EQ(d.unrefined, o.width_px) << ToString(m);
      }
    }
  }
  // Two pixels in: the 3-point methods still place it.
  s.centre.offset_px = 2.3;
  const StripeFrame frame = RenderStripes(o, {s});
  for (StripeMethod m : {StripeMethod::kParabola, StripeMethod::kGaussian}) {
    StripeDetector detector(With(m));
    const StripeDetection d = detector.Detect(frame.view());
    ASSERT_EQ(std::ssize(d.peaks), o.width_px) << ToString(m);
    EXPECT_LE(Compare(d, frame, StripeAxis::kColumns).max_px, 0.1) << ToString(m);
  }
}

TEST(StripeDetector, BadInputThrows) {
  StripeDetector detector;
  EXPECT_THROW(detector.Detect(StripeImage{}), Error);
  const std::vector<std::uint8_t> pixels(16, 100);
  EXPECT_THROW(detector.Detect(StripeImage::Mono8(pixels.data(), 0, 4)), Error);
  EXPECT_THROW(detector.Detect(StripeImage::Mono8(pixels.data(), 4, 0)), Error);
  EXPECT_THROW(detector.Detect(StripeImage::Mono8(nullptr, 4, 4)), Error);
  EXPECT_THROW(detector.Detect(StripeImage::Mono8(pixels.data(), 4, 4, 3)), Error);  // stride
  EXPECT_THROW(detector.Detect(StripeImage::Mono16(
                   reinterpret_cast<const std::uint16_t*>(pixels.data() + 1), 2, 2)),
               Error);  // misaligned Mono16
  // A 1x1 image is valid: it simply cannot hold a refined peak.
  const StripeDetection one = detector.Detect(StripeImage::Mono8(pixels.data(), 1, 1));
  EXPECT_TRUE(one.peaks.empty());

  const auto bad = [](auto change) {
    StripeDetectorOptions o;
    change(o);
    EXPECT_THROW(o.Check(), Error);
    EXPECT_THROW(StripeDetector{o}, Error);
  };
  bad([](StripeDetectorOptions& o) { o.threshold = 0; });
  bad([](StripeDetectorOptions& o) { o.window_px = 4; });
  bad([](StripeDetectorOptions& o) { o.window_px = 1; });
  bad([](StripeDetectorOptions& o) { o.max_second_peak_ratio = 0.0; });
  bad([](StripeDetectorOptions& o) { o.max_second_peak_ratio = 1.5; });
  bad([](StripeDetectorOptions& o) { o.min_separation_px = 0; });
  bad([](StripeDetectorOptions& o) { o.steger_sigma_px = 0.1; });
  bad([](StripeDetectorOptions& o) { o.steger_sigma_px = std::nan(""); });
  bad([](StripeDetectorOptions& o) { o.method = static_cast<StripeMethod>(42); });
  bad([](StripeDetectorOptions& o) { o.axis = static_cast<StripeAxis>(7); });
  EXPECT_NO_THROW(StripeDetectorOptions{}.Check());

  StripeRenderOptions r;
  r.width_px = 0;
  EXPECT_THROW(RenderStripes(r, {StripeSpec{}}), Error);
  EXPECT_THROW(RenderStripes(StripeRenderOptions{}, {}), Error);
}

TEST(StripeDetector, MethodNamesRoundTrip) {
  for (StripeMethod m : AllStripeMethods()) EXPECT_EQ(StripeMethodFromString(ToString(m)), m);
  EXPECT_FALSE(StripeMethodFromString("nope").has_value());
}

// ---------------------------------------------------------------------------------------------
// The fast row-by-row column scan against a naive column-by-column reference.

template <typename Pixel>
StripeDetection NaiveColumns(const StripeImage& image, const StripeDetectorOptions& o,
                             const StripeDetector& detector) {
  StripeDetection result;
  result.lines = image.width_px;
  const double saturation = MaxPixelValue(image.format);
  for (int u = 0; u < image.width_px; ++u) {
    std::vector<double> column(image.height_px);
    for (int v = 0; v < image.height_px; ++v) column[v] = image.Row<Pixel>(v)[u];
    int arg = 0;
    for (int v = 1; v < image.height_px; ++v) {
      if (column[v] > column[arg]) arg = v;
    }
    if (column[arg] < o.threshold) {
      ++result.below_threshold;
      continue;
    }
    double second = 0.0;
    for (int v = 1; v + 1 < image.height_px; ++v) {
      const bool local_max = column[v] > column[v - 1] && column[v] >= column[v + 1];
      if (local_max && std::abs(v - arg) > o.min_separation_px)
        second = std::max(second, column[v]);
    }
    if (o.max_second_peak_ratio < 1.0 && second >= o.threshold &&
        second > o.max_second_peak_ratio * column[arg]) {
      ++result.multiple_peaks;
      continue;
    }
    const std::optional<double> offset = detector.RefinePeak(column, arg, saturation);
    if (!offset) {
      ++result.unrefined;
      continue;
    }
    result.peaks.push_back({static_cast<double>(u), arg + *offset, column[arg]});
  }
  return result;
}

// A cluttered frame: noise, a stripe, a second stripe on part of the image, random spikes,
// saturated blobs and dark columns, so every branch of the scan is taken.
StripeFrame Cluttered(PixelFormat format, std::uint64_t seed, int width_px = 301,
                      int height_px = 77) {
  StripeRenderOptions o;
  o.width_px = width_px;  // 301: not a multiple of any vector width
  o.height_px = height_px;
  o.format = format;
  o.noise_sigma = format == PixelFormat::kMono8 ? 6.0 : 1500.0;
  o.background = format == PixelFormat::kMono8 ? 20.0 : 5000.0;
  o.seed = seed;
  const double top = MaxPixelValue(format);
  StripeSpec main = Stripe(2.0, 0.7 * top, 30.2);
  StripeSpec other = Stripe(1.2, 0.5 * top, 60.7);
  other.centre.wave_px = 25.0;
  StripeFrame frame = RenderStripes(o, {main, other});
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick_u(0, o.width_px - 1), pick_v(0, o.height_px - 1);
  for (int k = 0; k < 200; ++k) {
    const size_t v = static_cast<size_t>(pick_v(rng));
    const size_t i = v * o.width_px + pick_u(rng);
    if (format == PixelFormat::kMono8) {
      frame.mono8[i] = static_cast<std::uint8_t>(k % 2 ? 255 : 0);
    } else {
      frame.mono16[i] = static_cast<std::uint16_t>(k % 2 ? 65535 : 0);
    }
  }
  for (int v = 0; v < o.height_px; ++v) {
    for (int u = 100; u < std::min(110, o.width_px); ++u) {
      if (format == PixelFormat::kMono8) {
        frame.mono8[v * o.width_px + u] = 3;
      } else {
        frame.mono16[v * o.width_px + u] = 3;
      }
    }
  }
  return frame;
}

// The same lines, counts and peaks to the bit; `transposed`: the detection ran on the frame with
// rows and columns swapped, so its u is the reference's v.
void ExpectSameDetection(const StripeDetection& got, const StripeDetection& naive,
                         bool transposed) {
  EXPECT_EQ(got.lines, naive.lines);
  EXPECT_EQ(got.below_threshold, naive.below_threshold);
  EXPECT_EQ(got.multiple_peaks, naive.multiple_peaks);
  EXPECT_EQ(got.unrefined, naive.unrefined);
  ASSERT_EQ(got.peaks.size(), naive.peaks.size());
  for (size_t i = 0; i < got.peaks.size(); ++i) {
    const StripePeak& p = got.peaks[i];
    EXPECT_EQ(transposed ? p.v_px : p.u_px, naive.peaks[i].u_px) << i;
    EXPECT_EQ(transposed ? p.u_px : p.v_px, naive.peaks[i].v_px) << i;
    EXPECT_EQ(p.intensity, naive.peaks[i].intensity) << i;
  }
}

TEST(StripeDetector, FastColumnScanMatchesNaiveReference) {
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      const StripeFrame frame = Cluttered(f, seed);
      for (StripeMethod m : AllStripeMethods()) {
        for (double ratio : {0.5, 1.0}) {
          StripeDetectorOptions o = With(m);
          o.max_second_peak_ratio = ratio;
          o.threshold = f == PixelFormat::kMono8 ? 60 : 15000;
          StripeDetector detector(o);
          const StripeDetection fast = detector.Detect(frame.view());
          const StripeDetection naive =
              f == PixelFormat::kMono8 ? NaiveColumns<std::uint8_t>(frame.view(), o, detector)
                                       : NaiveColumns<std::uint16_t>(frame.view(), o, detector);
          SCOPED_TRACE(std::string(ToString(m)) + " ratio " + std::to_string(ratio));
          ExpectSameDetection(fast, naive, /*transposed=*/false);
          if (ratio < 1.0) {
            EXPECT_GT(fast.multiple_peaks, 0);
          }
        }
      }
    }
  }
}

// The frame with rows and columns swapped: its lines are the original's columns.
StripeFrame Transposed(const StripeFrame& frame) {
  StripeFrame t = frame;
  t.width_px = frame.height_px;
  t.height_px = frame.width_px;
  for (int v = 0; v < frame.height_px; ++v) {
    for (int u = 0; u < frame.width_px; ++u) {
      const size_t from = static_cast<size_t>(v) * frame.width_px + u;
      const size_t to = static_cast<size_t>(u) * t.width_px + v;
      if (frame.format == PixelFormat::kMono8) {
        t.mono8[to] = frame.mono8[from];
      } else {
        t.mono16[to] = frame.mono16[from];
      }
    }
  }
  return t;
}

// Detection along rows (DetectRows) of the transposed cluttered frames gives, line for line, the
// naive reference's answer on the original columns.
TEST(StripeDetector, FastRowScanMatchesNaiveReference) {
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      const StripeFrame frame = Cluttered(f, seed);
      const StripeFrame transposed = Transposed(frame);
      for (StripeMethod m : AllStripeMethods()) {
        for (double ratio : {0.5, 1.0}) {
          StripeDetectorOptions o = With(m);
          o.max_second_peak_ratio = ratio;
          o.threshold = f == PixelFormat::kMono8 ? 60 : 15000;
          StripeDetector reference(o);
          const StripeDetection naive =
              f == PixelFormat::kMono8 ? NaiveColumns<std::uint8_t>(frame.view(), o, reference)
                                       : NaiveColumns<std::uint16_t>(frame.view(), o, reference);
          o.axis = StripeAxis::kRows;
          StripeDetector detector(o);
          const StripeDetection rows = detector.Detect(transposed.view());
          SCOPED_TRACE(std::string(ToString(m)) + " ratio " + std::to_string(ratio));
          ExpectSameDetection(rows, naive, /*transposed=*/true);
          if (ratio < 1.0) {
            EXPECT_GT(rows.multiple_peaks, 0);
          }
        }
      }
    }
  }
}

// Rows of every length around the scan's vectors (32 Mono8 pixels, 16 Mono16) and separations
// under and over a vector: the row scan's searches and its second-peak test take each path.
TEST(StripeDetector, RowScanMatchesNaiveReferenceAtEveryRowLengthAndSeparation) {
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    for (int row_px : {3, 17, 31, 32, 33, 64, 65, 127, 128, 200, 517}) {
      const StripeFrame frame = Cluttered(f, 7, 113, row_px);
      const StripeFrame transposed = Transposed(frame);
      for (int separation : {1, 8, 31, 40, 100}) {
        StripeDetectorOptions o = With(StripeMethod::kSteger);
        o.min_separation_px = separation;
        o.threshold = f == PixelFormat::kMono8 ? 60 : 15000;
        StripeDetector reference(o);
        const StripeDetection naive = f == PixelFormat::kMono8
                                          ? NaiveColumns<std::uint8_t>(frame.view(), o, reference)
                                          : NaiveColumns<std::uint16_t>(frame.view(), o, reference);
        o.axis = StripeAxis::kRows;
        StripeDetector detector(o);
        SCOPED_TRACE("row of " + std::to_string(row_px) + " px, separation " +
                     std::to_string(separation));
        ExpectSameDetection(detector.Detect(transposed.view()), naive, /*transposed=*/true);
      }
    }
  }
}

TEST(StripeDetector, PaddedStrideAndReuseGiveTheSameResult) {
  const StripeFrame frame = Cluttered(PixelFormat::kMono8, 5);
  const int w = frame.width_px, h = frame.height_px, stride = w + 13;
  std::vector<std::uint8_t> padded(static_cast<size_t>(stride) * h, 0);
  for (int v = 0; v < h; ++v) {
    std::copy_n(frame.mono8.begin() + v * w, w, padded.begin() + v * stride);
  }
  StripeDetector detector;
  const StripeDetection packed = detector.Detect(frame.view());
  StripeDetection again;
  detector.Detect(StripeImage::Mono8(padded.data(), w, h, stride), &again);
  ASSERT_EQ(packed.peaks.size(), again.peaks.size());
  for (size_t i = 0; i < packed.peaks.size(); ++i) {
    EXPECT_EQ(packed.peaks[i].v_px, again.peaks[i].v_px);
  }
}

// ---------------------------------------------------------------------------------------------
// The renderer: what it promises the detectors.

TEST(StripeRender, IntegratesTheProfileOverEachPixel) {
  StripeRenderOptions o;
  o.width_px = 5;
  o.height_px = 60;
  o.format = PixelFormat::kMono16;
  o.background = 0.0;
  StripeSpec s = Stripe(2.0, 10000.0, 30.37);
  const StripeFrame frame = RenderStripes(o, {s});
  for (int u = 0; u < o.width_px; ++u) {
    double sum = 0.0, moment = 0.0;
    for (int v = 0; v < o.height_px; ++v) {
      sum += frame.mono16[v * o.width_px + u];
      moment += v * static_cast<double>(frame.mono16[v * o.width_px + u]);
    }
    // The integral of the profile, and its centre, up to rounding to integers.
    EXPECT_NEAR(sum, s.amplitude * s.sigma_px * std::sqrt(2.0 * std::numbers::pi), 30.0);
    EXPECT_NEAR(moment / sum, frame.truth_px[u], 1e-3);
    EXPECT_DOUBLE_EQ(frame.truth_px[u], s.centre.At(u));
  }
}

TEST(StripeRender, SameSeedSameFrameAndClipping) {
  StripeRenderOptions o = Small(StripeAxis::kColumns, PixelFormat::kMono8);
  o.noise_sigma = 5.0;
  const StripeFrame a = RenderStripes(o, {Stripe(1.5, 400.0)});
  const StripeFrame b = RenderStripes(o, {Stripe(1.5, 400.0)});
  EXPECT_EQ(a.mono8, b.mono8);
  o.seed = 2;
  EXPECT_NE(RenderStripes(o, {Stripe(1.5, 400.0)}).mono8, a.mono8);
  EXPECT_EQ(*std::max_element(a.mono8.begin(), a.mono8.end()), 255);
}

}  // namespace
}  // namespace uwscan::scanner
