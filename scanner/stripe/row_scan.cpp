#include "scanner/stripe/row_scan.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

#include "scanner/stripe/column_scan.hpp"

// GCC and clang warn that a 32-byte vector passed by value has another ABI without AVX. Every
// function below that takes or returns one is inlined into the clones, so none is ever passed
// in a call.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace uwscan::scanner::stripe_detail {
namespace {

// 32 bytes of pixels as one value (GCC's vector extension): one AVX2 register in the AVX2
// clone, two SSE2 registers in the default one. The loops below are written on these because
// the compiler, left to vectorise plain loops, reduces every chunk to one scalar (a chain of
// shuffles) and cannot keep a running maximum and a search in one pass.
template <typename Pixel>
struct Lanes;
template <>
struct Lanes<std::uint8_t> {
  typedef std::uint8_t Vector __attribute__((vector_size(32)));
};
template <>
struct Lanes<std::uint16_t> {
  typedef std::uint16_t Vector __attribute__((vector_size(32)));
};
template <typename Pixel>
using Vec = typename Lanes<Pixel>::Vector;
template <typename Pixel>
constexpr int kLanes = 32 / static_cast<int>(sizeof(Pixel));

template <typename Pixel>
[[gnu::always_inline]] inline Vec<Pixel> Load(const Pixel* p) {
  Vec<Pixel> v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

// Every lane `value` (a scalar operand of a vector operation is broadcast).
template <typename Pixel>
[[gnu::always_inline]] inline Vec<Pixel> Splat(Pixel value) {
  return Vec<Pixel>{} + value;
}

template <typename V>
[[gnu::always_inline]] inline V Max(V a, V b) {
  return a > b ? a : b;
}

template <typename Pixel>
[[gnu::always_inline]] inline Pixel HorizontalMax(Vec<Pixel> v) {
  Pixel m = 0;
  for (int i = 0; i < kLanes<Pixel>; ++i) m = std::max<Pixel>(m, v[i]);
  return m;
}

// The four 64-bit words of a lane mask (a comparison's result).
struct Words {
  std::uint64_t w[4];
};
template <typename Mask>
[[gnu::always_inline]] inline Words WordsOf(Mask m) {
  static_assert(sizeof(Mask) == sizeof(Words));
  Words words;
  std::memcpy(&words, &m, sizeof(words));
  return words;
}

template <typename Mask>
[[gnu::always_inline]] inline bool Any(Mask m) {
  const Words x = WordsOf(m);
  return ((x.w[0] | x.w[1]) | (x.w[2] | x.w[3])) != 0;
}

// The first set byte of a mask that has one.
template <typename Mask>
[[gnu::always_inline]] inline int FirstByte(Mask m) {
  const Words x = WordsOf(m);
  int word = 0;
  while (x.w[word] == 0) ++word;
  return 8 * word + __builtin_ctzll(x.w[word]) / 8;
}

// Lanes [0, n) all ones, the others zero, for n in [0, kLanes]: read at kLanes - n.
template <typename Pixel>
struct LowLanes {
  static constexpr auto kTable = [] {
    std::array<Pixel, 2 * kLanes<Pixel>> table{};
    for (int i = 0; i < kLanes<Pixel>; ++i) table[static_cast<std::size_t>(i)] = Pixel(~Pixel(0));
    return table;
  }();
};
template <typename Pixel>
[[gnu::always_inline]] inline Vec<Pixel> LanesBelow(int n) {
  return Load(LowLanes<Pixel>::kTable.data() + (kLanes<Pixel> - n));
}

// Whether row[u], u in [begin, end), holds a local maximum of at least `cut`: brighter than the
// pixel before, at least as bright as the one after (a flat top counts once). Needs
// 1 <= begin and end <= width - 1.
template <typename Pixel>
[[gnu::always_inline]] inline bool HasLocalMaximum(const Pixel* __restrict row, int begin, int end,
                                                   Pixel cut) {
  Pixel best = 0;
  for (int u = begin; u < end; ++u) {
    const Pixel peak =
        static_cast<Pixel>(-static_cast<int>((row[u] > row[u - 1]) & (row[u] >= row[u + 1])));
    best = std::max<Pixel>(best, row[u] & peak);
  }
  return best >= cut;
}

template <typename Pixel>
[[gnu::always_inline]] inline Pixel ScalarMax(const Pixel* row, int begin, int end) {
  Pixel m = 0;
  for (int u = begin; u < end; ++u) m = std::max(m, row[u]);
  return m;
}

// The lane-wise maximum of the whole vectors [first, last) of the row (zero when none).
template <typename Pixel>
[[gnu::always_inline]] inline Vec<Pixel> VectorMax(const Pixel* row, int first, int last) {
  Vec<Pixel> m{};
  for (int k = first; k < last; ++k) m = Max(m, Load(row + k * kLanes<Pixel>));
  return m;
}

// The brightest pixel of a row of `vectors` whole vectors and `width` pixels, the row's pixels
// read once, with four running maxima so that the loop is not one chain of dependent maxima.
template <typename Pixel>
[[gnu::always_inline]] inline Pixel RowMax(const Pixel* __restrict row, int vectors, int width) {
  constexpr int kL = kLanes<Pixel>;
  Vec<Pixel> m0{}, m1{}, m2{}, m3{};
  int k = 0;
  for (; k + 4 <= vectors; k += 4) {
    m0 = Max(m0, Load(row + k * kL));
    m1 = Max(m1, Load(row + (k + 1) * kL));
    m2 = Max(m2, Load(row + (k + 2) * kL));
    m3 = Max(m3, Load(row + (k + 3) * kL));
  }
  m0 = Max(m0, VectorMax(row, k, vectors));
  const Pixel in_vectors = HorizontalMax<Pixel>(Max(Max(m0, m1), Max(m2, m3)));
  return std::max(in_vectors, ScalarMax(row, vectors * kL, width));
}

// The first u with row[u] == top (which the row holds). On the way it gathers what the left
// side of the second-peak test needs: `vector`, the whole vector holding u (`vectors` if it lies
// in the tail), `before_last`, the lane-wise maximum of the vectors before vector - 1, and
// `last_before`, vector - 1 itself (zero when vector is 0).
template <typename Pixel>
[[gnu::always_inline]] inline int FindFirstTop(const Pixel* __restrict row, int vectors, Pixel top,
                                               int& vector, Vec<Pixel>& before_last,
                                               Vec<Pixel>& last_before) {
  constexpr int kL = kLanes<Pixel>;
  const Vec<Pixel> t = Splat(top);
  before_last = last_before = Splat(Pixel(0));
  int k = 0;
  // Four vectors per test first: the test (a mask reduced to one word) costs more than the
  // compares.
  for (; k + 4 <= vectors; k += 4) {
    const Vec<Pixel> v0 = Load(row + k * kL), v1 = Load(row + (k + 1) * kL);
    const Vec<Pixel> v2 = Load(row + (k + 2) * kL), v3 = Load(row + (k + 3) * kL);
    if (Any(((v0 == t) | (v1 == t)) | ((v2 == t) | (v3 == t)))) break;
    before_last = Max(Max(before_last, last_before), Max(Max(v0, v1), v2));
    last_before = v3;
  }
  for (; k < vectors; ++k) {
    const Vec<Pixel> v = Load(row + k * kL);
    if (Any(v == t)) break;
    before_last = Max(before_last, last_before);
    last_before = v;
  }
  vector = k;
  if (k < vectors)
    return k * kL + FirstByte(Load(row + k * kL) == t) / static_cast<int>(sizeof(Pixel));
  int u = vectors * kL;
  while (row[u] != top) ++u;
  return u;
}

// Whether a pixel of [0, end) may reach `cut` (false only when none does), given the lane-wise
// maximum of the whole vectors before the one holding `end`: that vector's lanes below `end`
// are added, or the scalar pixels when `end` lies past the row's `vectors` whole vectors.
template <typename Pixel>
[[gnu::always_inline]] inline bool MayReach(const Pixel* __restrict row, Vec<Pixel> whole_max,
                                            int end, int vectors, Pixel cut) {
  constexpr int kL = kLanes<Pixel>;
  const int k = end / kL;  // the vector holding `end`
  if (k < vectors) whole_max = Max(whole_max, Load(row + k * kL) & LanesBelow<Pixel>(end - k * kL));
  const Pixel tail = ScalarMax(row, std::max(vectors * kL, k * kL), end);
  return HorizontalMax<Pixel>(whole_max) >= cut || tail >= cut;
}

// Whether a pixel of [begin, width) may reach `cut` (false only when none does).
template <typename Pixel>
[[gnu::always_inline]] inline bool MayReachFrom(const Pixel* __restrict row, int begin, int vectors,
                                                int width, Pixel cut) {
  constexpr int kL = kLanes<Pixel>;
  const int k = begin / kL;  // the vector holding `begin`
  Vec<Pixel> m{};
  if (k < vectors) m = Load(row + k * kL) & ~LanesBelow<Pixel>(begin - k * kL);
  m = Max(m, VectorMax(row, k + 1, vectors));
  const Pixel tail = ScalarMax(row, std::max(vectors * kL, begin), width);
  return HorizontalMax<Pixel>(m) >= cut || tail >= cut;
}

// The scan of one row (a row shorter than a vector goes through the same steps on scalars).
template <typename Pixel>
[[gnu::always_inline]] inline RowFound ScanRow(const Pixel* __restrict row, int width,
                                               int separation, int threshold, double ratio) {
  constexpr int kL = kLanes<Pixel>;
  const int vectors = width / kL;
  RowFound found;
  const Pixel top = RowMax(row, vectors, width);
  int top_vector;
  Vec<Pixel> before_last, last_before;
  found.top = top;
  found.u0 = FindFirstTop(row, vectors, top, top_vector, before_last, last_before);
  if (!(ratio < 1.0 && top >= threshold)) return found;

  const Pixel cut = SecondPeakCut<Pixel>(top, threshold, ratio);
  const int reach = std::min(separation, width);  // no overflow past the row
  // Left of u0: [1, left_end). Its whole vectors are those before left_end's, which the search
  // passed (left_end's vector is u0's or the one before whenever the separation is under a
  // vector); otherwise they are read again.
  const int left_end = std::max(1, found.u0 - reach);
  const int left_vector = left_end / kL;
  Vec<Pixel> left_whole;
  if (left_vector == top_vector) {
    left_whole = Max(before_last, last_before);
  } else if (left_vector + 1 == top_vector) {
    left_whole = before_last;
  } else {
    left_whole = VectorMax(row, 0, left_vector);
  }
  const int right_begin = found.u0 + reach + 1;
  found.second_peak =
      (MayReach(row, left_whole, left_end, vectors, cut) &&
       HasLocalMaximum(row, 1, left_end, cut)) ||
      (right_begin < width - 1 && MayReachFrom(row, right_begin, vectors, width, cut) &&
       HasLocalMaximum(row, right_begin, width - 1, cut));
  return found;
}

template <typename Pixel>
[[gnu::always_inline]] inline void ScanRowsOf(const StripeImage& image, int begin, int end,
                                              int separation, int threshold, double ratio,
                                              RowFound* found) {
  for (int v = begin; v < end; ++v) {
    found[v - begin] = ScanRow(image.Row<Pixel>(v), image.width_px, separation, threshold, ratio);
  }
}

// The clones belong to these internal functions, not to the one the header declares (clang 14
// compiles a target_clones definition with an earlier plain declaration into its first clone
// alone, without dispatch).
__attribute__((target_clones("avx2", "default"))) void ScanRows8(const StripeImage& image,
                                                                 int begin, int end, int separation,
                                                                 int threshold, double ratio,
                                                                 RowFound* found) {
  ScanRowsOf<std::uint8_t>(image, begin, end, separation, threshold, ratio, found);
}

__attribute__((target_clones("avx2", "default"))) void ScanRows16(const StripeImage& image,
                                                                  int begin, int end,
                                                                  int separation, int threshold,
                                                                  double ratio, RowFound* found) {
  ScanRowsOf<std::uint16_t>(image, begin, end, separation, threshold, ratio, found);
}

}  // namespace

void ScanRows(const StripeImage& image, int begin, int end, int separation, int threshold,
              double ratio, RowFound* found) {
  if (image.format == PixelFormat::kMono8) {
    ScanRows8(image, begin, end, separation, threshold, ratio, found);
  } else {
    ScanRows16(image, begin, end, separation, threshold, ratio, found);
  }
}

}  // namespace uwscan::scanner::stripe_detail
