#pragma once

#include <cstdint>
#include <vector>

#include "scanner/stripe/stripe_detector.hpp"
#include "scanner/stripe/stripe_image.hpp"

namespace uwscan::scanner {

// A smooth stripe centre along the lines of an image: for kColumns, v(u) of column u; for kRows,
// u(v) of row v. centre(s) = offset_px + slope * (s - pivot_px) + wave_px * sin(2 pi s /
// period_px + phase_rad), pixels. A slope that is not a simple fraction spreads the centres
// evenly over sub-pixel positions.
struct StripeCurve {
  double offset_px = 500.3;
  double pivot_px = 0.0;
  double slope = 0.0137;
  double wave_px = 3.7;
  double period_px = 911.0;
  double phase_rad = 0.4;

  double At(double s) const;
};

// One stripe: its centre, its Gaussian cross-section (standard deviation sigma_px, pixels) and
// the height of that Gaussian above the background, image units.
struct StripeSpec {
  StripeCurve centre;
  double sigma_px = 1.5;
  double amplitude = 200.0;
};

struct StripeRenderOptions {
  int width_px = 2048;
  int height_px = 1088;
  PixelFormat format = PixelFormat::kMono8;
  StripeAxis axis = StripeAxis::kColumns;  // kColumns: centres v(u), one per column
  double background = 10.0;                // constant level, image units
  double noise_sigma = 0.0;                // additive Gaussian noise, image units (0 = clean)
  std::uint64_t seed = 1;                  // noise seed: same seed, same frame

  // Throws uwscan::Error naming the field when a value is not usable.
  void Check() const;
};

// A rendered frame that owns its pixels, and the exact centre of its first stripe per line.
struct StripeFrame {
  int width_px = 0;
  int height_px = 0;
  PixelFormat format = PixelFormat::kMono8;
  std::vector<std::uint8_t> mono8;    // used when format is kMono8, row-major, no padding
  std::vector<std::uint16_t> mono16;  // used when format is kMono16
  std::vector<double> truth_px;       // first stripe's centre per line (column or row), pixels

  StripeImage view() const;
};

// Renders stripes as a camera records them. Across the stripe the Gaussian is integrated over
// each pixel's extent ([v - 1/2, v + 1/2] for kColumns), so a pixel holds background +
// amplitude * integral of exp(-(t - c)^2 / (2 sigma^2)) dt; along the stripe the centre is
// taken constant over a pixel, so the exact centre of line s is centre.At(s). Stripes add up.
// Then noise, rounding to the nearest integer and clipping to [0, MaxPixelValue(format)]
// (saturation). Throws uwscan::Error on bad options or an empty stripe list.
StripeFrame RenderStripes(const StripeRenderOptions& options,
                          const std::vector<StripeSpec>& stripes);

}  // namespace uwscan::scanner
