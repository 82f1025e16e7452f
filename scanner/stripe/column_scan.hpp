#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "scanner/stripe/stripe_image.hpp"

// The column scan of the stripe detector (internal): each column's maximum, the first row with
// it, and which columns hold a second peak, from one pass over the frame in row order and, per
// group of columns, the few rows around the stripe read again row by row.
namespace uwscan::scanner::stripe_detail {

// Rows per block of the column scan. The one pass over the frame keeps each column's maximum
// per block (for 2048x1088 Mono8, 68 blocks: 139 KB, in cache); the rows of the blocks that hold
// a column's maximum or could hold a second peak are then read again (GroupArgs,
// GroupSecondPeaks).
constexpr int kBlockRows = 16;
constexpr std::uint16_t kNoBlock = 0xFFFF;

// Columns per group: the rows around the stripe are read again for a group at a time.
constexpr int kGroupColumns = 128;

// The lowest value that rejects a line whose brightest pixel is `top` as holding a second peak
// (at least `threshold` and above ratio * top): for integer values c, c >= threshold and
// c >= floor(ratio * top) + 1, at most the format's largest value.
template <typename Pixel>
Pixel SecondPeakCut(double top, int threshold, double ratio) {
  constexpr double kTop = static_cast<double>(std::numeric_limits<Pixel>::max());
  const double lowest = std::max<double>(threshold, std::floor(ratio * top) + 1.0);
  return static_cast<Pixel>(std::min(lowest, kTop));
}

// Buffers of the column scan, reused from frame to frame.
template <typename Pixel>
struct ColumnScratch {
  std::vector<Pixel> block_max;  // [block * width + u]
  std::vector<Pixel> max;
  std::vector<std::uint16_t> first_block;  // first block reaching max[u]
  std::vector<std::uint16_t> arg;
  // Second-peak candidates: the lowest value that could reject column u, and the first and
  // last block whose maximum reaches it (kNoBlock: none).
  std::vector<Pixel> cut;
  std::vector<std::uint16_t> first_candidate, last_candidate;
  // For the group of columns at hand (ScanGroup): whether each holds a second peak.
  std::array<std::uint8_t, kGroupColumns> group_reject;

  void Resize(int width, int blocks) {
    block_max.resize(static_cast<std::size_t>(width) * blocks);
    max.resize(width);
    first_block.resize(width);
    arg.resize(width);
    cut.resize(width);
    first_candidate.resize(width);
    last_candidate.resize(width);
  }
};

// The pass over the frame and its block maxima: scratch's max, first_block and, with
// reject_multiple, each column's cut and candidate blocks (max_second_peak_ratio `ratio`).
// Compiled for AVX2 too and chosen at run time; integer work, the same result either way.
void ScanColumns(const StripeImage& image, bool reject_multiple, int threshold, double ratio,
                 ColumnScratch<std::uint8_t>& scratch);
void ScanColumns(const StripeImage& image, bool reject_multiple, int threshold, double ratio,
                 ColumnScratch<std::uint16_t>& scratch);

// For the columns [u_begin, u_end) (at most kGroupColumns, after ScanColumns): arg, and with
// reject_multiple group_reject[u - u_begin], whether the column holds a second peak farther than
// `separation` rows from arg.
void ScanGroup(const StripeImage& image, int u_begin, int u_end, bool reject_multiple,
               int separation, ColumnScratch<std::uint8_t>& scratch);
void ScanGroup(const StripeImage& image, int u_begin, int u_end, bool reject_multiple,
               int separation, ColumnScratch<std::uint16_t>& scratch);

}  // namespace uwscan::scanner::stripe_detail
