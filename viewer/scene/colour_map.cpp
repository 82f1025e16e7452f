#include "viewer/scene/colour_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace uwscan::viewer {
namespace {

// Control colours of the continuous map at t = 0, 1/8, ..., 1.
constexpr std::array<Rgb, 9> kContinuous = {{{68, 1, 84},
                                             {71, 44, 122},
                                             {59, 81, 139},
                                             {44, 113, 142},
                                             {33, 144, 141},
                                             {39, 173, 129},
                                             {92, 200, 99},
                                             {170, 220, 50},
                                             {253, 231, 37}}};

constexpr std::array<Rgb, 10> kCategorical = {{{31, 119, 180},
                                               {255, 127, 14},
                                               {44, 160, 44},
                                               {214, 39, 40},
                                               {148, 103, 189},
                                               {140, 86, 75},
                                               {227, 119, 194},
                                               {127, 127, 127},
                                               {188, 189, 34},
                                               {23, 190, 207}}};

// Above this many values the percentiles are taken on an evenly strided sample: a colour range
// does not need the exact percentile of ten million points.
constexpr std::size_t kMaxRangeSamples = 1'000'000;

std::uint8_t Mix(std::uint8_t a, std::uint8_t b, double f) {
  return static_cast<std::uint8_t>(std::lround(a + (b - a) * f));
}

}  // namespace

Rgb ContinuousColour(double t) {
  if (std::isnan(t)) return kNoValue;
  const double x = std::clamp(t, 0.0, 1.0) * (kContinuous.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(x), kContinuous.size() - 2);
  const double f = x - static_cast<double>(i);
  const Rgb& a = kContinuous[i];
  const Rgb& b = kContinuous[i + 1];
  return {Mix(a.r, b.r, f), Mix(a.g, b.g, f), Mix(a.b, b.b, f)};
}

Rgb DivergingColour(double t) {
  if (std::isnan(t)) return kNoValue;
  // Moreland's cool-to-warm ends, a light middle distinct from kNoValue's grey.
  constexpr Rgb kLow{59, 76, 192}, kMiddle{236, 236, 236}, kHigh{180, 4, 38};
  const double x = std::clamp(t, 0.0, 1.0);
  const Rgb& a = x < 0.5 ? kLow : kMiddle;
  const Rgb& b = x < 0.5 ? kMiddle : kHigh;
  const double f = x < 0.5 ? 2.0 * x : 2.0 * x - 1.0;
  return {Mix(a.r, b.r, f), Mix(a.g, b.g, f), Mix(a.b, b.b, f)};
}

Rgb CategoricalColour(int i) {
  const int n = static_cast<int>(kCategorical.size());
  return kCategorical[static_cast<std::size_t>(((i % n) + n) % n)];
}

ScalarRange RobustRange(std::span<const float> values) {
  const std::size_t stride = std::max<std::size_t>(1, values.size() / kMaxRangeSamples);
  std::vector<float> finite;
  finite.reserve(values.size() / stride + 1);
  for (std::size_t i = 0; i < values.size(); i += stride) {
    if (std::isfinite(values[i])) finite.push_back(values[i]);
  }
  if (finite.empty()) return {};
  auto percentile = [&finite](double p) {
    const auto k =
        static_cast<std::ptrdiff_t>(std::floor(p * static_cast<double>(finite.size() - 1)));
    std::nth_element(finite.begin(), finite.begin() + k, finite.end());
    return static_cast<double>(finite[static_cast<std::size_t>(k)]);
  };
  ScalarRange range{percentile(0.01), percentile(0.99)};
  if (!(range.hi > range.lo)) {
    const double half = std::max(1e-9, std::abs(range.lo) * 1e-3);
    range = {range.lo - half, range.lo + half};
  }
  return range;
}

}  // namespace uwscan::viewer
