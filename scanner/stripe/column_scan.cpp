#include "scanner/stripe/column_scan.hpp"

#include <array>
#include <cstddef>
#include <utility>

namespace uwscan::scanner::stripe_detail {
namespace {

// The one pass over the frame, in row order: each column's maximum over each block of
// kBlockRows rows, and, while the block's maxima are in the first-level cache, each column's
// maximum so far and the first block reaching it.
template <typename Pixel>
[[gnu::always_inline]] inline void ColumnMaxima(const StripeImage& image,
                                                ColumnScratch<Pixel>& scratch) {
  const int width = image.width_px;
  const int height = image.height_px;
  const int blocks = (height + kBlockRows - 1) / kBlockRows;
  Pixel* __restrict max = scratch.max.data();
  std::uint16_t* __restrict first_block = scratch.first_block.data();
  std::fill(max, max + width, Pixel{0});
  std::fill(first_block, first_block + width, std::uint16_t{0});
  for (int b = 0; b < blocks; ++b) {
    Pixel* __restrict out = scratch.block_max.data() + static_cast<std::size_t>(b) * width;
    const int v_begin = b * kBlockRows;
    const int v_end = std::min(height, v_begin + kBlockRows);
    const Pixel* __restrict first = image.Row<Pixel>(v_begin);
    std::copy(first, first + width, out);
    for (int v = v_begin + 1; v < v_end; ++v) {
      const Pixel* __restrict row = image.Row<Pixel>(v);
      for (int u = 0; u < width; ++u) out[u] = std::max(out[u], row[u]);
    }
    const std::uint16_t bb = static_cast<std::uint16_t>(b);
    for (int u = 0; u < width; ++u) {
      const bool brighter = out[u] > max[u];
      max[u] = brighter ? out[u] : max[u];
      first_block[u] = brighter ? bb : first_block[u];
    }
  }
}

// Rows a group of columns (kGroupColumns) reads row by row at most; a group whose columns need
// rows farther apart (their brightest blocks, or their candidate blocks) is read column by
// column. A stripe crosses a group within a block or two.
constexpr int kGroupRows = 4 * kBlockRows;

// The least and the greatest of values[i], i in [0, n): two reductions the compiler vectorises.
inline std::pair<int, int> LeastAndGreatest(const std::uint16_t* __restrict values, int n) {
  std::uint16_t least = 0xFFFF;
  std::uint16_t greatest = 0;
  for (int i = 0; i < n; ++i) least = std::min(least, values[i]);
  for (int i = 0; i < n; ++i) greatest = std::max(greatest, values[i]);
  return {least, greatest};
}

// arg[u] for the columns [u_begin, u_end): the first row of u with its maximum, which lies in
// its first block reaching it (rows before that block are darker). Rows read from the last up,
// so that the first row matching is written last.
template <typename Pixel>
[[gnu::always_inline]] inline void GroupArgs(const StripeImage& image, int u_begin, int u_end,
                                             ColumnScratch<Pixel>& scratch) {
  const int height = image.height_px;
  const std::uint16_t* first_block = scratch.first_block.data();
  const auto block_end = [&](int u) { return std::min(height, (first_block[u] + 1) * kBlockRows); };
  const auto [first, last] = LeastAndGreatest(first_block + u_begin, u_end - u_begin);
  const int begin = first * kBlockRows;
  const int end = std::min(height, (last + 1) * kBlockRows);
  const Pixel* __restrict max = scratch.max.data();
  std::uint16_t* __restrict arg = scratch.arg.data();
  if (end - begin <= kGroupRows) {
    std::array<std::uint16_t, kGroupColumns> ends;  // of each column's first block at its max
    for (int u = u_begin; u < u_end; ++u)
      ends[u - u_begin] = static_cast<std::uint16_t>(block_end(u));
    for (int v = end - 1; v >= begin; --v) {
      const Pixel* __restrict row = image.Row<Pixel>(v);
      const std::uint16_t vv = static_cast<std::uint16_t>(v);
      for (int u = u_begin; u < u_end; ++u) {
        const bool here = (row[u] == max[u]) & (vv < ends[u - u_begin]);
        arg[u] = here ? vv : arg[u];
      }
    }
    return;
  }
  const std::ptrdiff_t step = image.stride_bytes / static_cast<std::ptrdiff_t>(sizeof(Pixel));
  for (int u = u_begin; u < u_end; ++u) {
    int v = first_block[u] * kBlockRows;
    for (const Pixel* p = image.Row<Pixel>(v) + u; *p != max[u]; p += step) ++v;
    arg[u] = static_cast<std::uint16_t>(v);
  }
}

// For every column, the blocks that could hold a value rejecting it as a line with two peaks
// (at least `threshold` and above ratio * max[u]): one vectorisable pass over the block maxima,
// so that the per-column check below reads only those blocks.
template <typename Pixel>
[[gnu::always_inline]] inline void SecondPeakCandidates(int width, int blocks, int threshold,
                                                        double ratio,
                                                        ColumnScratch<Pixel>& scratch) {
  for (int u = 0; u < width; ++u) {
    scratch.cut[u] = SecondPeakCut<Pixel>(scratch.max[u], threshold, ratio);
  }
  std::uint16_t* __restrict first = scratch.first_candidate.data();
  std::uint16_t* __restrict last = scratch.last_candidate.data();
  const Pixel* __restrict cut = scratch.cut.data();
  // One simple select per loop, which the compiler vectorises (the two fused did not): forwards
  // the last candidate is written last, backwards the first.
  const auto latest_candidate = [&](std::uint16_t* __restrict out, int b) {
    const Pixel* __restrict block = scratch.block_max.data() + static_cast<std::size_t>(b) * width;
    const std::uint16_t bb = static_cast<std::uint16_t>(b);
    for (int u = 0; u < width; ++u) out[u] = block[u] >= cut[u] ? bb : out[u];
  };
  std::fill(first, first + width, kNoBlock);
  std::fill(last, last + width, kNoBlock);
  for (int b = 0; b < blocks; ++b) latest_candidate(last, b);
  for (int b = blocks - 1; b >= 0; --b) latest_candidate(first, b);
}

// Whether column u holds a second peak that rejects it: an interior local maximum (brighter
// than the row above, at least as bright as the row below: a flat top counts once) farther than
// `separation` rows from the brightest pixel arg, at least `threshold` and above ratio * top,
// which for an integer value is at least cut[u] (SecondPeakCandidates). Only the candidate
// blocks are read, and the rows within `separation` of arg are skipped, not tested.
template <typename Pixel>
bool HasSecondPeak(const StripeImage& image, const ColumnScratch<Pixel>& scratch, int u,
                   int separation) {
  const int first = scratch.first_candidate[u];
  if (first == kNoBlock) return false;
  const int last = scratch.last_candidate[u];
  const Pixel cut = scratch.cut[u];
  const Pixel* column = image.Row<Pixel>(0) + u;
  const std::ptrdiff_t step = image.stride_bytes / static_cast<std::ptrdiff_t>(sizeof(Pixel));
  const auto peak_in = [&](int v_begin, int v_end) {  // rows [v_begin, v_end)
    const Pixel* p = column + v_begin * step;
    for (int v = v_begin; v < v_end; ++v, p += step) {
      if (*p > p[-step] && *p >= p[step] && *p >= cut) return true;
    }
    return false;
  };
  const int v_begin = std::max(1, first * kBlockRows);
  const int v_end = std::min(image.height_px - 1, (last + 1) * kBlockRows);
  const int arg = scratch.arg[u];
  const int reach = std::min(separation, 0xFFFF);  // rows are 16-bit: no overflow
  return peak_in(v_begin, std::min(v_end, arg - reach)) ||
         peak_in(std::max(v_begin, arg + reach + 1), v_end);
}

// Whether each column of [u_begin, u_end) holds a second peak (HasSecondPeak), into
// group_reject: the rows of the columns' candidate blocks read row by row for the whole group,
// or column by column when they lie far apart. Outside a column's candidate blocks no value
// reaches its cut, so the rows it would not read add nothing.
template <typename Pixel>
[[gnu::always_inline]] inline void GroupSecondPeaks(const StripeImage& image, int u_begin,
                                                    int u_end, int separation,
                                                    ColumnScratch<Pixel>& scratch) {
  const int n = u_end - u_begin;
  // kNoBlock (no candidate) is the greatest first block and a column's last is kNoBlock with
  // it: the least first block is that of a column with candidates, if any, and the greatest last
  // block below kNoBlock is found among those columns alone.
  const std::uint16_t first = LeastAndGreatest(scratch.first_candidate.data() + u_begin, n).first;
  if (first == kNoBlock) {
    std::fill(scratch.group_reject.begin(), scratch.group_reject.begin() + n, std::uint8_t{0});
    return;
  }
  std::array<std::uint16_t, kGroupColumns> lasts;  // each column's last candidate block, or 0
  for (int i = 0; i < n; ++i) {
    const std::uint16_t last = scratch.last_candidate[u_begin + i];
    lasts[i] = last == kNoBlock ? std::uint16_t{0} : last;
  }
  const int last = LeastAndGreatest(lasts.data(), n).second;
  const int begin = std::max(1, first * kBlockRows);
  const int end = std::min(image.height_px - 1, (last + 1) * kBlockRows);
  std::uint8_t* __restrict reject = scratch.group_reject.data();
  if (end - begin > kGroupRows) {
    for (int u = u_begin; u < u_end; ++u) {
      reject[u - u_begin] = HasSecondPeak(image, scratch, u, separation) ? 1 : 0;
    }
    return;
  }
  std::fill(reject, reject + n, std::uint8_t{0});
  // The rows around each column's brightest pixel that the test skips: those in [below, above].
  std::array<std::uint16_t, kGroupColumns> below, above;
  const int reach = std::min(separation, 0xFFFF);  // rows are 16-bit
  for (int i = 0; i < n; ++i) {
    const int arg = scratch.arg[u_begin + i];
    below[i] = static_cast<std::uint16_t>(std::max(arg - reach, 0));
    above[i] = static_cast<std::uint16_t>(std::min(arg + reach, 0xFFFF));
  }
  const Pixel* __restrict cut = scratch.cut.data() + u_begin;
  const std::uint16_t* __restrict skip_from = below.data();
  const std::uint16_t* __restrict skip_to = above.data();
  for (int v = begin; v < end; ++v) {
    const Pixel* __restrict up = image.Row<Pixel>(v - 1) + u_begin;
    const Pixel* __restrict row = image.Row<Pixel>(v) + u_begin;
    const Pixel* __restrict down = image.Row<Pixel>(v + 1) + u_begin;
    const std::uint16_t vv = static_cast<std::uint16_t>(v);
    for (int i = 0; i < n; ++i) {
      const bool peak = (row[i] > up[i]) & (row[i] >= down[i]) & (row[i] >= cut[i]);
      const bool apart = (vv < skip_from[i]) | (vv > skip_to[i]);
      reject[i] |= static_cast<std::uint8_t>(peak & apart);
    }
  }
}

// The passes over the whole frame and its block maxima, compiled for AVX2 too and chosen at run
// time (never -march=native against Debian's PCL, DESIGN.md): integer work, the same result on
// either path.
template <typename Pixel>
[[gnu::always_inline]] inline void ScanColumnsOf(const StripeImage& image, bool reject_multiple,
                                                 int threshold, double ratio,
                                                 ColumnScratch<Pixel>& scratch) {
  ColumnMaxima<Pixel>(image, scratch);
  if (reject_multiple) {
    SecondPeakCandidates(image.width_px, (image.height_px + kBlockRows - 1) / kBlockRows, threshold,
                         ratio, scratch);
  }
}

__attribute__((target_clones("avx2", "default"))) void ScanColumnClones(
    const StripeImage& image, bool reject_multiple, int threshold, double ratio,
    ColumnScratch<std::uint8_t>& scratch) {
  ScanColumnsOf(image, reject_multiple, threshold, ratio, scratch);
}

__attribute__((target_clones("avx2", "default"))) void ScanColumnClones(
    const StripeImage& image, bool reject_multiple, int threshold, double ratio,
    ColumnScratch<std::uint16_t>& scratch) {
  ScanColumnsOf(image, reject_multiple, threshold, ratio, scratch);
}

// The row-wise passes of a group of columns, compiled for AVX2 too and chosen at run time.
template <typename Pixel>
[[gnu::always_inline]] inline void ScanGroupOf(const StripeImage& image, int u_begin, int u_end,
                                               bool reject_multiple, int separation,
                                               ColumnScratch<Pixel>& scratch) {
  GroupArgs(image, u_begin, u_end, scratch);
  if (reject_multiple) GroupSecondPeaks(image, u_begin, u_end, separation, scratch);
}

__attribute__((target_clones("avx2", "default"))) void ScanGroupClones(
    const StripeImage& image, int u_begin, int u_end, bool reject_multiple, int separation,
    ColumnScratch<std::uint8_t>& scratch) {
  ScanGroupOf(image, u_begin, u_end, reject_multiple, separation, scratch);
}

__attribute__((target_clones("avx2", "default"))) void ScanGroupClones(
    const StripeImage& image, int u_begin, int u_end, bool reject_multiple, int separation,
    ColumnScratch<std::uint16_t>& scratch) {
  ScanGroupOf(image, u_begin, u_end, reject_multiple, separation, scratch);
}

}  // namespace

// The clones belong to internal functions, not to these that the header declares: clang 14
// compiles a target_clones definition with an earlier plain declaration into its first clone
// alone, without dispatch (cone_batch.cpp).
void ScanColumns(const StripeImage& image, bool reject_multiple, int threshold, double ratio,
                 ColumnScratch<std::uint8_t>& scratch) {
  ScanColumnClones(image, reject_multiple, threshold, ratio, scratch);
}

void ScanColumns(const StripeImage& image, bool reject_multiple, int threshold, double ratio,
                 ColumnScratch<std::uint16_t>& scratch) {
  ScanColumnClones(image, reject_multiple, threshold, ratio, scratch);
}

void ScanGroup(const StripeImage& image, int u_begin, int u_end, bool reject_multiple,
               int separation, ColumnScratch<std::uint8_t>& scratch) {
  ScanGroupClones(image, u_begin, u_end, reject_multiple, separation, scratch);
}

void ScanGroup(const StripeImage& image, int u_begin, int u_end, bool reject_multiple,
               int separation, ColumnScratch<std::uint16_t>& scratch) {
  ScanGroupClones(image, u_begin, u_end, reject_multiple, separation, scratch);
}

}  // namespace uwscan::scanner::stripe_detail
