#pragma once

#include <optional>

namespace uwscan::scanner::stripe_detail {

// Where a slope-like response s(k) (positive before the peak, negative after) falls through zero
// within kCrossingReach samples of 0, linearly interpolated; std::nullopt if it does not.
constexpr int kCrossingReach = 2;

template <typename Slope>
std::optional<double> ZeroCrossingNear(const Slope& s) {
  const double s0 = s(0);
  if (s0 > 0.0) {
    double previous = s0;
    for (int k = 1; k <= kCrossingReach; ++k) {
      const double next = s(k);
      if (next <= 0.0) return k - 1 + previous / (previous - next);
      previous = next;
    }
    return std::nullopt;
  }
  double next = s0;
  for (int k = -1; k >= -kCrossingReach; --k) {
    const double previous = s(k);
    if (previous > 0.0) return k + previous / (previous - next);
    next = previous;
  }
  return std::nullopt;
}

}  // namespace uwscan::scanner::stripe_detail
