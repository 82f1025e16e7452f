#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "scanner/stripe/zero_crossing.hpp"

namespace uwscan::scanner::stripe_detail {

// Steger's refinement (the zero crossing of the Gaussian-derivative slopes, ZeroCrossingNear)
// of many lines at once. A line's slope is a chain of dependent additions; across lines the sums
// are independent, and the compiler runs several lines per instruction. Each line's slope adds
// the same products in the same order from 0 as the per-line refinement, and its crossing takes
// the same pair of samples and the same arithmetic, so the offsets are the same bits.
//
// A line is added with its samples about its brightest one (a single or double top below
// saturation, its support inside the image: the caller's to check); the offsets come once the
// batch is computed. Buffers are kept from batch to batch.
class StegerBatch {
 public:
  // Lines per batch: their samples and slopes (15 + 5 doubles a line for sigma 1.5) stay in the
  // first-level cache.
  static constexpr int kLines = 128;

  // d1: the integrated Gaussian-derivative kernel, 2r + 1 weights for k = -r..r.
  explicit StegerBatch(std::span<const double> d1);

  // Samples needed each side of the brightest one: r + kCrossingReach.
  int support() const { return support_; }
  void Clear() { lines_ = 0; }

  // Adds the line whose brightest sample is *centre, its neighbours `step` apart, at least
  // support() of them each side; returns its place in the batch. At most kLines per batch.
  template <typename Pixel>
  int Add(const Pixel* centre, std::ptrdiff_t step) {
    std::uint16_t* out = samples_.data() + lines_;
    if (support_ == kDefaultSupport) {  // the loop unrolled: 7 % more frames per second
      for (int k = -kDefaultSupport; k <= kDefaultSupport; ++k) {
        out[(k + kDefaultSupport) * kLines] = centre[k * step];
      }
      return lines_++;
    }
    const Pixel* p = centre - support_ * step;
    for (int k = -support_; k <= support_; ++k, p += step, out += kLines) *out = *p;
    return lines_++;
  }

  // The slopes and crossings of the lines added since Clear.
  void Compute();

  // Whether the line's crossing was found, and then where (*offset, from its brightest sample).
  bool Refined(int line, double* offset) const {
    *offset = offset_[static_cast<std::size_t>(line)];
    return found_[static_cast<std::size_t>(line)] != 0;
  }

 private:
  // The samples each side of the peak for the default steger_sigma_px of 1.5: a kernel radius
  // of ceil(3 sigma) = 5 and the crossing's reach.
  static constexpr int kDefaultSupport = 5 + kCrossingReach;

  std::vector<double> d1_;
  int r_;
  int support_;
  int lines_ = 0;
  std::vector<std::uint16_t> samples_;  // [(k + support) * kLines + line]
  std::vector<double> values_;          // the samples as the slopes multiply them
  std::vector<double> slopes_;          // [(k + kCrossingReach) * kLines + line]
  std::array<double, kLines> offset_{};
  std::array<std::uint8_t, kLines> found_{};
};

}  // namespace uwscan::scanner::stripe_detail
