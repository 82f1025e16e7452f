#include "viewer/plots/legend_place.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace uwscan::viewer {
namespace {

// A point as the axis draws it: the logarithm on a log axis; NaN where it cannot be drawn.
double OnAxis(double v, bool log) {
  if (!std::isfinite(v) || (log && !(v > 0.0))) return std::numeric_limits<double>::quiet_NaN();
  return log ? std::log10(v) : v;
}

// Every place the chart draws something, on the axes' scales.
std::vector<std::array<double, 2>> DrawnSamples(const PlotSpec& spec) {
  constexpr int kSamplesPerSegment = 32;
  std::vector<std::array<double, 2>> samples;
  auto add = [&](double x, double y) {
    const double ax = OnAxis(x, spec.log_x), ay = OnAxis(y, spec.log_y);
    if (std::isfinite(ax) && std::isfinite(ay)) samples.push_back({ax, ay});
  };
  for (const PlotSeries& s : spec.series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (s.style == SeriesStyle::kPoints) {
        add(s.x[i], s.y[i]);
      } else if (s.style == SeriesStyle::kBars) {
        for (int k = 0; k <= kSamplesPerSegment; ++k) add(s.x[i], s.y[i] * k / kSamplesPerSegment);
      } else if (i + 1 < n) {
        for (int k = 0; k < kSamplesPerSegment; ++k) {
          const double t = static_cast<double>(k) / kSamplesPerSegment;
          add(s.x[i] + t * (s.x[i + 1] - s.x[i]), s.y[i] + t * (s.y[i + 1] - s.y[i]));
        }
      } else {
        add(s.x[i], s.y[i]);
      }
    }
  }
  return samples;
}

}  // namespace

LegendPlace PlaceLegend(const PlotSpec& spec) {
  const std::vector<std::array<double, 2>> samples = DrawnSamples(spec);
  if (samples.empty()) return LegendPlace::kTopRight;
  std::array<double, 2> lo{samples[0]}, hi{samples[0]};
  for (const auto& p : samples) {
    for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  }
  if (spec.y_range) {
    lo[1] = OnAxis(spec.y_range->first, spec.log_y);
    hi[1] = OnAxis(spec.y_range->second, spec.log_y);
  }
  // Which third a coordinate falls in (0, 1, 2), the middle one for a range of no width.
  auto third = [&](double v, int a) {
    if (!(hi[a] > lo[a])) return 1;
    return std::clamp(static_cast<int>(3.0 * (v - lo[a]) / (hi[a] - lo[a])), 0, 2);
  };
  std::array<std::array<int, 3>, 3> count{};  // [row from the bottom][column from the left]
  for (const auto& p : samples)
    ++count[static_cast<std::size_t>(third(p[1], 1))][static_cast<std::size_t>(third(p[0], 0))];
  const std::array<std::pair<LegendPlace, int>, 5> places{
      {{LegendPlace::kTopRight, count[2][2]},
       {LegendPlace::kTopLeft, count[2][0]},
       {LegendPlace::kTopCentre, count[2][1]},
       {LegendPlace::kBottomRight, count[0][2]},
       {LegendPlace::kBottomLeft, count[0][0]}}};
  return std::min_element(places.begin(), places.end(),
                          [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

}  // namespace uwscan::viewer
