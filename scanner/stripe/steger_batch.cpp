#include "scanner/stripe/steger_batch.hpp"

#include <algorithm>

namespace uwscan::scanner::stripe_detail {
namespace {

constexpr int kLines = StegerBatch::kLines;

// The zero crossing of ZeroCrossingNear for a batch of lines, from their slopes d(k),
// slopes[(k + kCrossingReach) * kLines + line]: the same pair of samples chosen and the
// same arithmetic, without a branch (which way the crossing lies is a coin toss per line).
// found[line] says whether there is one; offset[line] is it.
[[gnu::always_inline]] inline void BatchCrossings(const double* __restrict slopes, int lines,
                                                  double* __restrict offset,
                                                  std::uint8_t* __restrict found) {
  static_assert(kCrossingReach == 2);
  const double* __restrict back2 = slopes;
  const double* __restrict back1 = slopes + kLines;
  const double* __restrict at0 = slopes + 2 * kLines;
  const double* __restrict ahead1 = slopes + 3 * kLines;
  const double* __restrict ahead2 = slopes + 4 * kLines;
  for (int line = 0; line < lines; ++line) {
    const double sm2 = back2[line];
    const double sm1 = back1[line];
    const double s0 = at0[line];
    const double s1 = ahead1[line];
    const double s2 = ahead2[line];
    const bool rising = s0 > 0.0;
    // Rising: between 0 and 1 when d(1) <= 0, else between 1 and 2 when d(2) <= 0.
    const bool near_ahead = s1 <= 0.0;
    const double ahead_base = near_ahead ? 0.0 : 1.0;
    const double ahead_previous = near_ahead ? s0 : s1;
    const double ahead_next = near_ahead ? s1 : s2;
    const bool ahead_found = near_ahead | (s2 <= 0.0);
    // Falling: between -1 and 0 when d(-1) > 0, else between -2 and -1 when d(-2) > 0.
    const bool near_back = sm1 > 0.0;
    const double back_base = near_back ? -1.0 : -2.0;
    const double back_previous = near_back ? sm1 : sm2;
    const double back_next = near_back ? s0 : sm1;
    const bool back_found = near_back | (sm2 > 0.0);
    const double base = rising ? ahead_base : back_base;
    const double previous = rising ? ahead_previous : back_previous;
    const double next = rising ? ahead_next : back_next;
    offset[line] = base + previous / (previous - next);
    found[line] = static_cast<std::uint8_t>((rising & ahead_found) | (!rising & back_found));
  }
}

constexpr int kSlopeLanes = 8;

// The slopes d(k), |k| <= kCrossingReach, of a batch of lines, each as StegerOffset sums it
// (the same products added in the same order from 0, so the same bits), and their zero
// crossings (BatchCrossings). One line's sum is a chain of dependent additions; across lines
// they are independent, and the compiler vectorises them.
// samples[(k + support) * kLines + line], |k| <= support = r + kCrossingReach, and values
// the same as doubles; slopes[(k + kCrossingReach) * kLines + line]; d1 holds 2r + 1
// weights. kSlopeLanes lines are summed together, held in registers across the kernel's taps.
__attribute__((target_clones("avx2", "default"))) void BatchSlopes(
    const std::uint16_t* __restrict samples, const double* __restrict d1, int r, int lines,
    double* __restrict values, double* __restrict slopes, double* __restrict offset,
    std::uint8_t* __restrict found) {
  const int support = r + kCrossingReach;
  // Whole groups of lanes: the lines past `lines` hold earlier batches' samples, unused.
  const int padded = (lines + kSlopeLanes - 1) / kSlopeLanes * kSlopeLanes;
  for (int i = 0; i < (2 * support + 1) * kLines; ++i) {
    values[i] = static_cast<double>(samples[i]);
  }
  for (int k = -kCrossingReach; k <= kCrossingReach; ++k) {
    for (int first = 0; first < padded; first += kSlopeLanes) {
      std::array<double, kSlopeLanes> sum{};
      for (int j = -r; j <= r; ++j) {
        const double* __restrict p = values + (k + j + support) * kLines + first;
        const double w = d1[j + r];
        for (int lane = 0; lane < kSlopeLanes; ++lane) sum[lane] += p[lane] * w;
      }
      std::copy(sum.begin(), sum.end(), slopes + (k + kCrossingReach) * kLines + first);
    }
  }
  BatchCrossings(slopes, lines, offset, found);
}

}  // namespace

StegerBatch::StegerBatch(std::span<const double> d1)
    : d1_(d1.begin(), d1.end()),
      r_(static_cast<int>(d1.size() / 2)),
      support_(r_ + kCrossingReach),
      samples_(static_cast<std::size_t>(2 * support_ + 1) * kLines),
      values_(samples_.size()),
      slopes_(static_cast<std::size_t>(2 * kCrossingReach + 1) * kLines) {}

void StegerBatch::Compute() {
  BatchSlopes(samples_.data(), d1_.data(), r_, lines_, values_.data(), slopes_.data(),
              offset_.data(), found_.data());
}

}  // namespace uwscan::scanner::stripe_detail
