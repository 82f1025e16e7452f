#include "scanner/sim/frame_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

namespace uwscan::scanner::sim {
namespace {

// Reflectance of the reference target for which effects.image.peak_level is given.
constexpr double kReferenceReflectance = 0.5;
// The stripe profile is drawn out to this many standard deviations.
constexpr double kProfileExtentSigma = 5.0;
constexpr double kGlowSigmaPx = 3.0;

// A fast deterministic source of standard normal numbers for per-pixel noise: 4096 quantiles
// of N(0, 1) picked by 12 random bits from a 64-bit generator. Sensor noise needs millions
// per frame; the quantised distribution differs from N(0, 1) by far less than the noise
// itself matters for (sub-1e-3 in its standard deviation).
class FastNormal {
 public:
  explicit FastNormal(std::uint64_t seed) : state_(seed ^ 0x9E3779B97F4A7C15ull) {
    static const std::array<float, 4096> table = MakeTable();
    table_ = &table;
  }
  float operator()() {
    if (bits_left_ < 12) {
      word_ = Next();
      bits_left_ = 60;
    }
    const float value = (*table_)[word_ & 4095u];
    word_ >>= 12;
    bits_left_ -= 12;
    return value;
  }

 private:
  static std::array<float, 4096> MakeTable() {
    std::array<float, 4096> t{};
    for (size_t i = 0; i < t.size(); ++i) {
      const double p = (static_cast<double>(i) + 0.5) / t.size();
      t[i] = static_cast<float>(InverseNormal(p));
    }
    return t;
  }
  // Inverse standard normal CDF by bisection on erfc (used once, for the table).
  static double InverseNormal(double p) {
    double lo = -10.0, hi = 10.0;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  std::uint64_t Next() {  // splitmix64
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::uint64_t state_;
  std::uint64_t word_ = 0;
  int bits_left_ = 0;
  const std::array<float, 4096>* table_;
};

double StripeSigmaPx(const TracedPeak& peak, const SimulationEffects& effects, double focal_px) {
  double sigma2 = effects.image.blur_sigma_px * effects.image.blur_sigma_px;
  if (effects.beam.on) {
    // Beam diameter (1/e^2, = 4 sigma) grows with the distance travelled in water.
    const double diameter_m =
        effects.beam.diameter_m + effects.beam.divergence_rad * peak.laser_range_m;
    const double sigma_px = focal_px * 0.25 * diameter_m / std::max(peak.z_C_m, 1e-3);
    sigma2 += sigma_px * sigma_px;
  }
  return std::sqrt(sigma2);
}

// Stripe height at the camera: a Lambertian target of this reflectance lit at this incidence,
// seen from this range, through attenuating water when that stage is on.
double StripeAmplitude(const TracedPeak& peak, const SimulationEffects& effects,
                       double attenuation_per_m) {
  const double range_m = std::max(peak.camera_range_m, 0.05);
  double level = effects.image.peak_level * (peak.reflectance / kReferenceReflectance) *
                 peak.cos_incidence / (range_m * range_m);
  if (effects.attenuation) {
    level *= std::exp(-attenuation_per_m * (peak.laser_range_m + peak.camera_range_m));
  }
  return level;
}

// Adds amplitude * integral over each pixel of exp(-(t - centre)^2 / (2 sigma^2)) along one
// image line, with multiplicative speckle per pixel when `speckle` is given.
void AddProfile(float* line, int length, std::ptrdiff_t step, double centre, double sigma,
                double amplitude, double speckle_contrast, FastNormal* speckle) {
  const double reach = kProfileExtentSigma * sigma + 1.0;
  const int first = std::max(0, static_cast<int>(std::floor(centre - reach)));
  const int last = std::min(length - 1, static_cast<int>(std::ceil(centre + reach)));
  const double scale = amplitude * sigma * std::sqrt(M_PI / 2.0);
  const double inv = 1.0 / (std::sqrt(2.0) * sigma);
  double cdf_lo = std::erf((first - 0.5 - centre) * inv);
  for (int i = first; i <= last; ++i) {
    const double cdf_hi = std::erf((i + 0.5 - centre) * inv);
    double value = scale * (cdf_hi - cdf_lo);
    if (speckle != nullptr) value *= std::max(0.0, 1.0 + speckle_contrast * (*speckle)());
    line[i * step] += static_cast<float>(value);
    cdf_lo = cdf_hi;
  }
}

void AddGlow(std::vector<float>& image, int width, int height, const GlowSample& glow) {
  const int reach = static_cast<int>(std::ceil(3.0 * kGlowSigmaPx));
  const int u0 = static_cast<int>(std::lround(glow.px.x()));
  const int v0 = static_cast<int>(std::lround(glow.px.y()));
  const double inv2s2 = 1.0 / (2.0 * kGlowSigmaPx * kGlowSigmaPx);
  for (int v = std::max(0, v0 - reach); v <= std::min(height - 1, v0 + reach); ++v) {
    for (int u = std::max(0, u0 - reach); u <= std::min(width - 1, u0 + reach); ++u) {
      const double d2 =
          (u - glow.px.x()) * (u - glow.px.x()) + (v - glow.px.y()) * (v - glow.px.y());
      image[static_cast<size_t>(v) * width + u] +=
          static_cast<float>(glow.level * std::exp(-d2 * inv2s2));
    }
  }
}

}  // namespace

StripeFrame RenderFrame(const FrameRenderInput& input, const SimulationEffects& effects,
                        std::uint64_t seed) {
  const int width = input.width_px;
  const int height = input.height_px;
  const bool rows = input.axis == StripeAxis::kRows;
  std::vector<float> image(static_cast<size_t>(width) * height,
                           effects.ambient.on ? static_cast<float>(effects.ambient.level) : 0.0f);

  StripeFrame frame;
  frame.width_px = width;
  frame.height_px = height;
  frame.format = effects.image.format;
  frame.truth_px.assign(static_cast<size_t>(rows ? height : width),
                        std::numeric_limits<double>::quiet_NaN());

  FastNormal speckle(seed * 2 + 1);
  for (const TracedPeak& peak : input.peaks) {
    const int line = static_cast<int>(std::lround(rows ? peak.px.y() : peak.px.x()));
    const double centre = rows ? peak.px.x() : peak.px.y();
    if (std::isnan(frame.truth_px[static_cast<size_t>(line)])) {
      frame.truth_px[static_cast<size_t>(line)] = centre;
    }
    float* start =
        rows ? &image[static_cast<size_t>(line) * width] : &image[static_cast<size_t>(line)];
    AddProfile(start, rows ? width : height, rows ? 1 : width, centre,
               StripeSigmaPx(peak, effects, input.focal_px),
               StripeAmplitude(peak, effects, input.attenuation_per_m), effects.speckle.contrast,
               effects.speckle.on ? &speckle : nullptr);
  }
  if (effects.backscatter.on) {
    for (const GlowSample& glow : input.glow) AddGlow(image, width, height, glow);
  }

  const int max_value = MaxPixelValue(frame.format);
  // Noise standard deviation per integer level: shot noise plus read noise.
  std::vector<float> noise_sigma;
  if (effects.sensor_noise.on) {
    noise_sigma.resize(static_cast<size_t>(max_value) + 1);
    for (int level = 0; level <= max_value; ++level) {
      noise_sigma[static_cast<size_t>(level)] = static_cast<float>(
          std::sqrt(level / effects.sensor_noise.electrons_per_level +
                    effects.sensor_noise.read_sigma * effects.sensor_noise.read_sigma));
    }
  }
  FastNormal noise(seed * 2 + 2);
  auto quantise = [&](float value) {
    if (!noise_sigma.empty()) {
      const int level = std::clamp(static_cast<int>(value + 0.5f), 0, max_value);
      value += noise_sigma[static_cast<size_t>(level)] * noise();
    }
    return std::clamp(static_cast<int>(std::lround(value)), 0, max_value);
  };
  if (frame.format == PixelFormat::kMono8) {
    frame.mono8.resize(image.size());
    for (size_t i = 0; i < image.size(); ++i)
      frame.mono8[i] = static_cast<std::uint8_t>(quantise(image[i]));
  } else {
    frame.mono16.resize(image.size());
    for (size_t i = 0; i < image.size(); ++i)
      frame.mono16[i] = static_cast<std::uint16_t>(quantise(image[i]));
  }
  return frame;
}

}  // namespace uwscan::scanner::sim
