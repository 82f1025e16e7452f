#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "scanner/stripe/stripe_image.hpp"

namespace uwscan::scanner {

// How the sub-pixel centre of a stripe is found around the brightest pixel of a line.
// Every method except kMaximum is invariant to a constant background, or estimates it as the
// minimum over the window (centre of mass, Gaussian).
enum class StripeMethod : std::uint8_t {
  kMaximum = 0,   // the brightest pixel (integer; the middle of a flat top)
  kCentreOfMass,  // intensity-weighted mean over window_px, minus the window's minimum
  kGaussian,      // 3-point Gaussian fit: log-parabola through the peak and its neighbours
  kParabola,      // 3-point parabola through the peak and its neighbours
  kBlaisRioux,    // zero crossing of the 4th-order derivative filter of Blais & Rioux (1986)
  kSteger,        // zero crossing of the Gaussian-derivative response (Steger 1998, 1-D)
  // The two zero-crossing methods look for the crossing within 2 px of the brightest pixel
  // and interpolate it linearly between the two samples around it.
};

// "maximum", "centre_of_mass", "gaussian", "parabola", "blais_rioux", "steger".
const char* ToString(StripeMethod method);
// Inverse of ToString; std::nullopt for an unknown name.
std::optional<StripeMethod> StripeMethodFromString(std::string_view name);
// All methods, in enum order.
std::span<const StripeMethod> AllStripeMethods();

// Which image lines carry one peak each.
enum class StripeAxis : std::uint8_t {
  kColumns = 0,  // one peak per column u, its position v sub-pixel (a roughly horizontal stripe)
  kRows,         // one peak per row v, its position u sub-pixel (a roughly vertical stripe)
};

struct StripeDetectorOptions {
  // Default: the most accurate method measured (`uwscan bench stripe`: clean and noisy stripes
  // of sigma 1.5 and 3 px) at about the speed of the others.
  StripeMethod method = StripeMethod::kSteger;
  StripeAxis axis = StripeAxis::kColumns;
  // Minimum intensity of the brightest pixel of a line for it to carry a peak, image units
  // (Mono8: 0..255, Mono16: 0..65535), >= 1.
  int threshold = 40;
  // Centre of mass: window width, pixels, odd, >= 3, centred on the brightest pixel. Also the
  // window over which the Gaussian method takes its background (the minimum).
  int window_px = 11;
  // Multiple-peak rejection: a line is dropped when its highest local maximum farther than
  // min_separation_px from the brightest pixel is >= threshold and > max_second_peak_ratio
  // times the brightest pixel. 1 disables it (and its search for second peaks). In (0, 1].
  double max_second_peak_ratio = 0.5;
  int min_separation_px = 8;  // pixels, >= 1
  // Steger: standard deviation of the Gaussian whose derivatives are convolved, pixels,
  // in [0.5, 10].
  double steger_sigma_px = 1.5;

  // Throws uwscan::Error naming the field when a value is not usable.
  void Check() const;
};

// One stripe peak, in OpenCV pixel coordinates (the centre of the top-left pixel is (0, 0)).
// Along the scanned line's own index the coordinate is an integer: u_px for kColumns, v_px for
// kRows.
struct StripePeak {
  double u_px = 0.0;
  double v_px = 0.0;
  double intensity = 0.0;  // value of the brightest pixel of the line, image units
};

// Peaks in detector order (line by line, increasing u for kColumns, increasing v for kRows)
// and why the other lines carry none.
struct StripeDetection {
  std::vector<StripePeak> peaks;
  int lines = 0;            // lines scanned (image width for kColumns, height for kRows)
  int below_threshold = 0;  // brightest pixel < threshold
  int multiple_peaks = 0;   // rejected by the second-peak test
  int unrefined = 0;        // support outside the image, or no zero crossing was found
};

// Finds at most one stripe peak per image column (or row) of Mono8 and Mono16 frames.
//
// For kColumns the frame is read once, row by row, keeping each column's maximum over every
// block of 16 rows (loops over contiguous rows that the compiler vectorises); hence each
// column's maximum and the first block reaching it. Then, for groups of 128 columns, the few
// rows around the stripe are read again row by row: for the first row with each column's
// maximum and, with multiple-peak rejection on, in the blocks whose maximum could reject a
// column, for a local maximum outside min_separation_px of its brightest pixel (a group whose
// columns need rows far apart is read column by column). Only then is each column's profile
// read around its maximum and refined to sub-pixel by the configured method; Steger's slopes
// are summed for a group's lines together, in the same order as for one, so with the same
// bits. kRows reads each row directly. Buffers are reused from frame to frame: once grown to
// the frame size, nothing more is allocated.
//
// Edges: a line whose refinement needs pixels beyond the image (a stripe whose brightest pixel
// lies within the method's support of the border: 1 px for the 3-point methods, 4 for
// Blais-Rioux, ceil(3 steger_sigma_px) + 2 for Steger; see SupportRadius()) carries no peak; the
// centre of mass shrinks its window symmetrically instead. A saturated top (the brightest pixel at
// the format's maximum) or any flat top of 3 or more equal pixels is located, whatever the method,
// as the midpoint of the two sub-pixel crossings of the half level between the top and the window's
// minimum.
//
// Not thread-safe (it keeps scratch buffers): use one detector per thread. Move-only.
class StripeDetector {
 public:
  explicit StripeDetector(const StripeDetectorOptions& options = {});
  ~StripeDetector();
  StripeDetector(StripeDetector&&) noexcept;
  StripeDetector& operator=(StripeDetector&&) noexcept;

  const StripeDetectorOptions& options() const { return options_; }

  // Throws uwscan::Error when the image is empty or malformed, or taller than 65535 rows for
  // kColumns. `result` is overwritten; its storage is reused.
  void Detect(const StripeImage& image, StripeDetection* result);
  StripeDetection Detect(const StripeImage& image);

  // The refinement step on its own: the sub-pixel position (in profile indices) of the peak
  // whose brightest sample is profile[peak_index] (the first of equal maxima), or std::nullopt
  // when the method cannot place it (see the class comment). `saturation` is the format's
  // maximum pixel value. Uses the same arithmetic as Detect.
  std::optional<double> RefinePeak(std::span<const double> profile, int peak_index,
                                   double saturation) const;

  // Pixels needed on each side of the brightest pixel by the configured method.
  int SupportRadius() const { return support_radius_; }

 private:
  template <typename Pixel>
  void DetectColumns(const StripeImage& image, StripeDetection* result);
  template <typename Pixel>
  void DetectRows(const StripeImage& image, StripeDetection* result);

  StripeDetectorOptions options_;
  int support_radius_ = 1;
  int steger_radius_ = 0;
  std::vector<double> steger_d1_;  // integrated Gaussian first-derivative kernel, k = -R..R

  struct Scratch;  // buffers of the column scan, reused across frames
  std::unique_ptr<Scratch> scratch_;
};

}  // namespace uwscan::scanner
