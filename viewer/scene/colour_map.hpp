#pragma once

#include <cstdint>
#include <span>

namespace uwscan::viewer {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

// A continuous perceptual colour map (viridis-like: dark blue through green to yellow), linear
// between nine control colours. t in [0, 1]; values outside are clamped, NaN gives kNoValue.
Rgb ContinuousColour(double t);

// A diverging map for signed values (blue below the middle, light grey at it, red above), t in
// [0, 1] with 0.5 the middle; values outside are clamped, NaN gives kNoValue.
Rgb DivergingColour(double t);

// Points whose scalar is missing (NaN: no truth for that point).
inline constexpr Rgb kNoValue{128, 128, 128};

// The i-th of ten distinct categorical colours (cycling), for files, objects and trajectories.
Rgb CategoricalColour(int i);

// A closed scalar interval mapped onto the colour map, lo < hi.
struct ScalarRange {
  double lo = 0.0;
  double hi = 1.0;
  // Position of `value` in the range, not clamped.
  double Normalise(double value) const { return (value - lo) / (hi - lo); }
};

// The range that colours a set of scalars: from the 1st to the 99th percentile of the finite
// values (a few outliers must not squash every other colour into one end), widened around the
// value when they are all equal. {0, 1} when no value is finite. Deterministic.
ScalarRange RobustRange(std::span<const float> values);

}  // namespace uwscan::viewer
