#include "scanner/stripe/stripe_render.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kTwoPi = 6.283185307179586;

}  // namespace

double StripeCurve::At(double s) const {
  return offset_px + slope * (s - pivot_px) +
         wave_px * std::sin(kTwoPi * s / period_px + phase_rad);
}

void StripeRenderOptions::Check() const {
  const OptionChecks check("StripeRenderOptions");
  check.AtLeast("width_px", width_px, 1, "px");
  check.AtLeast("height_px", height_px, 1, "px");
  check.NonNegative("background", background, "image units");
  check.NonNegative("noise_sigma", noise_sigma, "image units");
}

StripeImage StripeFrame::view() const {
  return format == PixelFormat::kMono8 ? StripeImage::Mono8(mono8.data(), width_px, height_px)
                                       : StripeImage::Mono16(mono16.data(), width_px, height_px);
}

StripeFrame RenderStripes(const StripeRenderOptions& o, const std::vector<StripeSpec>& stripes) {
  o.Check();
  if (stripes.empty()) throw Error("stripe render: no stripe given");
  for (const StripeSpec& s : stripes) {
    if (!(s.sigma_px > 0.0 && std::isfinite(s.sigma_px))) {
      throw Error("stripe render: sigma_px: expected > 0");
    }
    if (!std::isfinite(s.amplitude) || !(s.centre.period_px != 0.0)) {
      throw Error("stripe render: amplitude must be finite and period_px non-zero");
    }
  }
  const bool columns = o.axis == StripeAxis::kColumns;
  const int lines = columns ? o.width_px : o.height_px;
  const int length = columns ? o.height_px : o.width_px;

  // Intensities in double, line by line (line = column for kColumns), then quantised.
  std::vector<double> value(static_cast<size_t>(o.width_px) * o.height_px, o.background);
  const auto index = [&](int line, int k) {
    return columns ? static_cast<size_t>(k) * o.width_px + line
                   : static_cast<size_t>(line) * o.width_px + k;
  };
  StripeFrame frame;
  frame.width_px = o.width_px;
  frame.height_px = o.height_px;
  frame.format = o.format;
  frame.truth_px.resize(lines);
  for (size_t i = 0; i < stripes.size(); ++i) {
    const StripeSpec& s = stripes[i];
    // integral_{a}^{b} exp(-(t-c)^2 / (2 sigma^2)) dt = sigma sqrt(pi/2) [erf(.)] from a to b.
    const double scale = s.amplitude * s.sigma_px * std::sqrt(kTwoPi / 4.0);
    const double to_erf = 1.0 / (s.sigma_px * std::sqrt(2.0));
    const int reach = static_cast<int>(std::ceil(8.0 * s.sigma_px)) + 1;
    for (int line = 0; line < lines; ++line) {
      const double c = s.centre.At(line);
      if (i == 0) frame.truth_px[line] = c;
      if (!std::isfinite(c)) continue;
      const int k0 = std::max(0, static_cast<int>(std::floor(c)) - reach);
      const int k1 = std::min(length - 1, static_cast<int>(std::floor(c)) + reach);
      for (int k = k0; k <= k1; ++k) {
        value[index(line, k)] +=
            scale * (std::erf((k + 0.5 - c) * to_erf) - std::erf((k - 0.5 - c) * to_erf));
      }
    }
  }
  if (o.noise_sigma > 0.0) {
    std::mt19937_64 rng(o.seed);
    std::normal_distribution<double> noise(0.0, o.noise_sigma);
    for (double& x : value) x += noise(rng);
  }
  const double top = MaxPixelValue(o.format);
  const auto quantise = [top](double x) { return std::clamp(std::round(x), 0.0, top); };
  if (o.format == PixelFormat::kMono8) {
    frame.mono8.resize(value.size());
    std::transform(value.begin(), value.end(), frame.mono8.begin(),
                   [&](double x) { return static_cast<std::uint8_t>(quantise(x)); });
  } else {
    frame.mono16.resize(value.size());
    std::transform(value.begin(), value.end(), frame.mono16.begin(),
                   [&](double x) { return static_cast<std::uint16_t>(quantise(x)); });
  }
  return frame;
}

}  // namespace uwscan::scanner
