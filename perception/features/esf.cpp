#include "perception/features/esf.hpp"

#include <omp.h>
#include <pcl/features/esf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "perception/cloud/pcl_conversion.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {
namespace {

constexpr int kBins = 64;  // bins per sub-histogram
// PCL rejects a triangle whose squared area (Heron's s(s-a)(s-b)(s-c)) is at most 0.001 in grid
// units, i.e. with the cloud scaled to a radius of half the grid. We compute the squared area
// from a cross product instead, which does not cancel catastrophically on thin triangles.
constexpr float kMinSquaredArea = 0.001f;
// ComputeEsf gives up when fewer than `samples` triangles pass in this many draws per sample.
constexpr long long kMaxDrawsPerSample = 200;
// Lines with at most this many occupied voxels are "out". This and the two constants below are
// PCL's absolute voxel counts, tuned for its 64^3 grid; they are not rescaled for other sizes.
constexpr int kMaxInVoxelsOfOutLine = 7;
// A triangle is "out" when its three lines cross at most this many occupied voxels in all.
constexpr int kMaxInVoxelsOfOutTriangle = 21;
// ... and "in" when fewer than this many of its voxels are free.
constexpr int kMaxFreeVoxelsOfInTriangle = 4;

// Sub-histogram weights of PCL 1.13, in output order (A3 in/out/mixed, D3 in/out/mixed, D2
// in/out/mixed, D2 ratio), with its extra factor 0.5 on D2 in and D2 ratio folded in.
constexpr std::array<double, 10> kWeights = {0.5, 0.5, 0.5, 0.5, 0.5, 1.0, 0.5, 2.0, 2.0, 1.0};

enum LineClass { kIn = 0, kOut = 1, kMixed = 2 };

// Bit set of occupied voxels of a size^3 grid, addressed by (x * size + y) * size + z.
class OccupancyGrid {
 public:
  explicit OccupancyGrid(int size)
      : size_(size), bits_((static_cast<std::size_t>(size) * size * size + 63) / 64, 0) {}

  int size() const { return size_; }
  bool Contains(const Eigen::Vector3i& v) const {
    return (v.array() >= 0).all() && (v.array() < size_).all();
  }
  std::ptrdiff_t Index(const Eigen::Vector3i& v) const {
    return (static_cast<std::ptrdiff_t>(v.x()) * size_ + v.y()) * size_ + v.z();
  }
  void Set(std::ptrdiff_t i) { bits_[i >> 6] |= std::uint64_t{1} << (i & 63); }
  int Get(std::ptrdiff_t i) const { return static_cast<int>((bits_[i >> 6] >> (i & 63)) & 1); }

 private:
  int size_;
  std::vector<std::uint64_t> bits_;
};

// The cloud centred on its centroid and scaled so that its farthest point is grid_size / 2 grid
// units away, with each point's voxel; or the reason the cloud has no ESF.
struct ScaledCloud {
  std::string reason;
  std::vector<Eigen::Vector3f> points;  // grid units
  std::vector<Eigen::Vector3i> voxels;
};

// PCL's voxel of a coordinate in grid units: floor(x) + h below zero, ceil(x) + h - 1 from zero
// up; clamped so that rounding at the boundary cannot leave the grid.
int VoxelOf(float x, int grid_size) {
  const int h = grid_size / 2;
  const int v =
      x < 0.0f ? static_cast<int>(std::floor(x)) + h : static_cast<int>(std::ceil(x)) + h - 1;
  return std::clamp(v, 0, grid_size - 1);
}

// A uniform index in [0, n), n < 2^31, from the high 32 bits of one draw (bias below 2^-32 * n).
int DrawIndex(std::mt19937_64& rng, std::uint64_t n) {
  return static_cast<int>(((rng() >> 32) * n) >> 32);
}

float SquaredArea(const Eigen::Vector3f& p1, const Eigen::Vector3f& p2, const Eigen::Vector3f& p3) {
  return 0.25f * (p2 - p1).cross(p3 - p1).squaredNorm();
}

// Why ESF cannot take `cloud` whatever its shape (empty, not finite, too few or too many
// points); empty when it can.
std::string UnusableReason(const PointCloud& cloud) {
  const std::size_t n = cloud.size();
  if (n == 0) return "empty cloud";
  if (!cloud.origin.allFinite()) return "the cloud's origin is not finite";
  for (std::size_t i = 0; i < n; ++i) {
    if (!cloud.points[i].allFinite()) {
      return "point " + std::to_string(i) + " is not finite (NaN or inf)";
    }
  }
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    return std::to_string(n) + " points; ESF takes at most 2^31 - 1";
  }
  if (n < 3) return std::to_string(n) + " point(s); ESF needs at least 3 distinct points";
  return "";
}

// The points' centroid and their largest distance from it. Offsets from the cloud's origin
// suffice: ESF does not depend on where the cloud is.
std::pair<Eigen::Vector3d, double> CentroidAndRadius(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) centroid += p.cast<double>();
  centroid /= static_cast<double>(points.size());
  double radius = 0.0;
  for (const Eigen::Vector3f& p : points) {
    radius = std::max(radius, (p.cast<double>() - centroid).norm());
  }
  return {centroid, radius};
}

// The index of the point farthest by `distance` (the first of equals).
template <typename Distance>
std::size_t Farthest(const std::vector<Eigen::Vector3f>& points, const Distance& distance) {
  std::size_t best = 0;
  float best_d = -1.0f;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float d = distance(points[i]);
    if (d > best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

// Why no triangle of the cloud is usefully thick (fewer than 3 distinct points, or all
// collinear); empty when some is. `scaled` are the cloud's points in grid units. A is the point
// farthest from the centroid, B the one farthest from A, C the one farthest from the line AB:
// when even ABC is thinner than PCL's area threshold, no triangle of the cloud is thicker.
std::string FlatReason(const PointCloud& cloud, const std::vector<Eigen::Vector3f>& scaled) {
  const std::size_t a = Farthest(scaled, [](const Eigen::Vector3f& p) { return p.squaredNorm(); });
  const Eigen::Vector3f& pa = scaled[a];
  const std::size_t b =
      Farthest(scaled, [&](const Eigen::Vector3f& p) { return (p - pa).squaredNorm(); });
  const Eigen::Vector3f& pb = scaled[b];
  const Eigen::Vector3f ab = pb - pa;
  const std::size_t c =
      Farthest(scaled, [&](const Eigen::Vector3f& p) { return ab.cross(p - pa).squaredNorm(); });
  const bool two_distinct = std::all_of(
      cloud.points.begin(), cloud.points.end(),
      [&](const Eigen::Vector3f& p) { return p == cloud.points[a] || p == cloud.points[b]; });
  if (two_distinct) return "only 2 distinct points; ESF needs at least 3";
  if (!(SquaredArea(pa, pb, scaled[c]) > kMinSquaredArea)) {
    return "all points are collinear (no triangle above the area threshold)";
  }
  return "";
}

std::vector<Eigen::Vector3i> VoxelsOf(const std::vector<Eigen::Vector3f>& points, int grid_size) {
  std::vector<Eigen::Vector3i> voxels(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    voxels[i] = {VoxelOf(p.x(), grid_size), VoxelOf(p.y(), grid_size), VoxelOf(p.z(), grid_size)};
  }
  return voxels;
}

ScaledCloud ScaleToGrid(const PointCloud& cloud, int grid_size) {
  ScaledCloud out;
  out.reason = UnusableReason(cloud);
  if (!out.reason.empty()) return out;
  const auto [centroid, radius] = CentroidAndRadius(cloud.points);
  if (!(radius > 0.0)) {
    out.reason = "all " + std::to_string(cloud.size()) + " points are identical";
    return out;
  }
  const double scale = 0.5 * grid_size / radius;
  out.points.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out.points[i] = ((cloud.points[i].cast<double>() - centroid) * scale).cast<float>();
  }
  out.reason = FlatReason(cloud, out.points);
  if (!out.reason.empty()) return out;
  out.voxels = VoxelsOf(out.points, grid_size);
  return out;
}

// Occupied voxels: each point's voxel and its 26 neighbours.
OccupancyGrid Occupancy(const std::vector<Eigen::Vector3i>& voxels, int grid_size) {
  OccupancyGrid grid(grid_size);
  for (const Eigen::Vector3i& v : voxels) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const Eigen::Vector3i u = v + Eigen::Vector3i(dx, dy, dz);
          if (grid.Contains(u)) grid.Set(grid.Index(u));
        }
      }
    }
  }
  return grid;
}

struct LineTrace {
  int in = 0;     // occupied voxels crossed
  int count = 0;  // voxels crossed
};

// 3-D Bresenham from voxel `from` towards `to`, as PCL traces it: the first max(L, 1) voxels of
// the line, L the largest per-axis step count (the end voxel itself is not visited when L > 0).
// Walks the grid's linear index, so each step is an add and a bit test.
LineTrace TraceLine(const OccupancyGrid& grid, const Eigen::Vector3i& from,
                    const Eigen::Vector3i& to) {
  const std::ptrdiff_t g = grid.size();
  const std::array<std::ptrdiff_t, 3> stride = {g * g, g, 1};
  std::array<int, 3> len;
  std::array<std::ptrdiff_t, 3> step;
  for (int k = 0; k < 3; ++k) {
    const int d = to[k] - from[k];
    len[k] = std::abs(d);
    step[k] = d < 0 ? -stride[k] : stride[k];
  }
  int major = 2;
  if (len[0] >= len[1] && len[0] >= len[2]) {
    major = 0;
  } else if (len[1] >= len[2]) {
    major = 1;
  }
  const int m1 = (major + 1) % 3;
  const int m2 = (major + 2) % 3;
  const int length = len[major];
  int err1 = 2 * len[m1] - length;
  int err2 = 2 * len[m2] - length;
  // Masks instead of branches: whether a minor axis advances is data dependent and would
  // mispredict often.
  const int inc1 = 2 * len[m1], inc2 = 2 * len[m2], dec = 2 * length;
  const std::ptrdiff_t step1 = step[m1], step2 = step[m2], step0 = step[major];
  std::ptrdiff_t i = grid.Index(from);
  int in = 0;
  for (int n = 1; n < length; ++n) {
    in += grid.Get(i);
    const int advance1 = -static_cast<int>(err1 > 0);  // all ones when advancing, else 0
    const int advance2 = -static_cast<int>(err2 > 0);
    i += step0 + (step1 & advance1) + (step2 & advance2);
    err1 += inc1 - (dec & advance1);
    err2 += inc2 - (dec & advance2);
  }
  in += grid.Get(i);
  return {in, std::max(length, 1)};
}

LineClass Classify(const LineTrace& t) {
  if (t.in >= t.count - 1) return kIn;
  if (t.in <= kMaxInVoxelsOfOutLine) return kOut;
  return kMixed;
}

// round(value / max * 63), PCL's binning of a normalised value in [0, 1].
int Bin(float value_over_max) {
  return std::clamp(static_cast<int>(std::floor(value_over_max * (kBins - 1) + 0.5f)), 0,
                    kBins - 1);
}

// Bin of the angle between two directions with the given |cosine|, folded into [0, pi/2]:
// round(acos(c) / (pi/2) * 63), found among the cosines of the 63 bin boundaries instead of
// calling acos.
int AngleBin(float abs_cosine) {
  // Decreasing cosines of the boundaries, cos((k + 0.5) / 63 * pi/2), padded to 64 with -inf.
  static const std::array<float, kBins> kBoundaries = [] {
    std::array<float, kBins> b{};
    for (int k = 0; k < kBins - 1; ++k) {
      b[k] = static_cast<float>(std::cos((k + 0.5) / (kBins - 1) * std::numbers::pi / 2.0));
    }
    b[kBins - 1] = -std::numeric_limits<float>::infinity();
    return b;
  }();
  // The number of boundaries the angle has passed (cosine at or above abs_cosine), by a
  // branch-free binary search.
  int k = 0;
  for (int half = kBins / 2; half > 0; half /= 2) {
    k += kBoundaries[k + half - 1] >= abs_cosine ? half : 0;
  }
  return k;
}

struct Triangle {
  int i1, i2, i3;
  float d12, d13, d23;  // side lengths, grid units
  float d3;             // sqrt(area)
};

// Integer accumulators, so that the sum does not depend on how samples are split over threads.
struct Counts {
  std::array<std::array<long long, kBins>, 3> a3{};  // voxel counts of opposite sides
  std::array<std::array<long long, kBins>, 3> d3{};
  std::array<std::array<long long, kBins>, 3> d2{};
  std::array<long long, kBins> ratio{};

  void Add(const Counts& o) {
    for (int c = 0; c < 3; ++c) {
      for (int b = 0; b < kBins; ++b) {
        a3[c][b] += o.a3[c][b];
        d3[c][b] += o.d3[c][b];
        d2[c][b] += o.d2[c][b];
      }
    }
    for (int b = 0; b < kBins; ++b) ratio[b] += o.ratio[b];
  }
};

void AccumulateTriangle(const Triangle& t, const ScaledCloud& cloud, const OccupancyGrid& grid,
                        float max_d2, float max_d3, Counts& counts) {
  const Eigen::Vector3f& p1 = cloud.points[t.i1];
  const Eigen::Vector3f& p2 = cloud.points[t.i2];
  const Eigen::Vector3f& p3 = cloud.points[t.i3];
  const Eigen::Vector3f u21 = (p2 - p1) / t.d12;
  const Eigen::Vector3f u31 = (p3 - p1) / t.d13;
  const Eigen::Vector3f u23 = (p2 - p3) / t.d23;
  const int th1 = AngleBin(std::abs(u21.dot(u31)));  // at p1, opposite side 2-3
  const int th2 = AngleBin(std::abs(u23.dot(u31)));  // at p3, opposite side 1-2
  const int th3 = AngleBin(std::abs(u23.dot(u21)));  // at p2, opposite side 1-3

  const LineTrace l12 = TraceLine(grid, cloud.voxels[t.i1], cloud.voxels[t.i2]);
  const LineTrace l13 = TraceLine(grid, cloud.voxels[t.i1], cloud.voxels[t.i3]);
  const LineTrace l23 = TraceLine(grid, cloud.voxels[t.i2], cloud.voxels[t.i3]);
  const std::array<std::pair<LineTrace, float>, 3> lines = {
      std::pair{l12, t.d12}, std::pair{l13, t.d13}, std::pair{l23, t.d23}};
  for (const auto& [line, length] : lines) {
    const LineClass c = Classify(line);
    counts.d2[c][Bin(length / max_d2)] += 1;
    if (c == kMixed) {
      counts.ratio[Bin(static_cast<float>(line.in) / static_cast<float>(line.count))] += 1;
    }
  }

  const int in_sum = l12.in + l13.in + l23.in;
  const int count_sum = l12.count + l13.count + l23.count;
  LineClass c = kMixed;
  if (in_sum <= kMaxInVoxelsOfOutTriangle) {
    c = kOut;
  } else if (count_sum - in_sum < kMaxFreeVoxelsOfInTriangle) {
    c = kIn;
  }
  counts.a3[c][th1] += l23.count;
  counts.a3[c][th2] += l12.count;
  counts.a3[c][th3] += l13.count;
  counts.d3[c][Bin(t.d3 / max_d3)] += 1;
}

EsfDescriptor ToHistogram(const Counts& counts) {
  std::array<double, 10 * kBins> h{};
  for (int c = 0; c < 3; ++c) {
    for (int b = 0; b < kBins; ++b) {
      // PCL adds (voxel count) / 32 per angle, whatever the grid size.
      h[c * kBins + b] = kWeights[c] * static_cast<double>(counts.a3[c][b]) / 32.0;
      h[(3 + c) * kBins + b] = kWeights[3 + c] * static_cast<double>(counts.d3[c][b]);
      h[(6 + c) * kBins + b] = kWeights[6 + c] * static_cast<double>(counts.d2[c][b]);
    }
  }
  for (int b = 0; b < kBins; ++b) {
    h[9 * kBins + b] = kWeights[9] * static_cast<double>(counts.ratio[b]);
  }
  double sum = 0.0;
  for (double v : h) sum += v;
  EsfDescriptor out;
  for (int i = 0; i < 10 * kBins; ++i) out[i] = static_cast<float>(h[i] / sum);
  return out;
}

}  // namespace

void EsfOptions::Check() const {
  const OptionChecks check("EsfOptions");
  check.InRange("samples", samples, 1, 10'000'000);
  check.Require(grid_size >= 16 && grid_size <= 256 && grid_size % 2 == 0, "grid_size",
                "an even number in [16, 256]", grid_size);
  check.AtLeast("threads", threads, 0);
}

EsfResult ComputeEsf(const PointCloud& cloud, const EsfOptions& options) {
  options.Check();
  EsfResult result;
  const ScaledCloud scaled = ScaleToGrid(cloud, options.grid_size);
  if (!scaled.reason.empty()) {
    result.reason = scaled.reason;
    return result;
  }
  const std::uint64_t n = scaled.points.size();

  // Draw the triangles in sequence (the only step that uses the generator), then bin them in
  // parallel into integer counts.
  std::mt19937_64 rng(options.seed);
  std::vector<Triangle> triangles;
  triangles.reserve(static_cast<std::size_t>(options.samples));
  float max_d2 = 0.0f;
  float max_d3 = 0.0f;
  const long long max_draws = kMaxDrawsPerSample * options.samples;
  long long draws = 0;
  while (triangles.size() < static_cast<std::size_t>(options.samples) && draws < max_draws) {
    ++draws;
    const int i1 = DrawIndex(rng, n);
    const int i2 = DrawIndex(rng, n);
    const int i3 = DrawIndex(rng, n);
    if (i1 == i2 || i1 == i3 || i2 == i3) continue;
    const Eigen::Vector3f& p1 = scaled.points[i1];
    const Eigen::Vector3f& p2 = scaled.points[i2];
    const Eigen::Vector3f& p3 = scaled.points[i3];
    const float area2 = SquaredArea(p1, p2, p3);
    if (!(area2 > kMinSquaredArea)) continue;
    const Triangle t{i1,
                     i2,
                     i3,
                     (p2 - p1).norm(),
                     (p3 - p1).norm(),
                     (p2 - p3).norm(),
                     std::sqrt(std::sqrt(area2))};
    max_d2 = std::max({max_d2, t.d12, t.d13, t.d23});
    max_d3 = std::max(max_d3, t.d3);
    triangles.push_back(t);
  }
  if (triangles.size() < static_cast<std::size_t>(options.samples)) {
    result.reason = "only " + std::to_string(triangles.size()) + " of " +
                    std::to_string(options.samples) + " non-degenerate triangles found in " +
                    std::to_string(max_draws) + " draws (nearly collinear cloud)";
    return result;
  }

  const OccupancyGrid grid = Occupancy(scaled.voxels, options.grid_size);
  Counts total;
  const long long count = static_cast<long long>(triangles.size());
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel num_threads(threads)
  {
    Counts local;
#pragma omp for schedule(static)
    for (long long i = 0; i < count; ++i) {
      AccumulateTriangle(triangles[static_cast<std::size_t>(i)], scaled, grid, max_d2, max_d3,
                         local);
    }
#pragma omp critical(uwscan_esf_merge)
    total.Add(local);
  }
  result.histogram = ToHistogram(total);
  result.ok = true;
  return result;
}

EsfResult ComputePclEsf(const PointCloud& cloud) {
  EsfResult result;
  constexpr int kGrid = 64;  // PCL's GRIDSIZE
  const ScaledCloud scaled = ScaleToGrid(cloud, kGrid);
  if (!scaled.reason.empty()) {
    result.reason = scaled.reason;
    return result;
  }
  // PCL draws until 20000 triples pass; make sure enough of them do.
  constexpr int kTrials = 4000;
  constexpr int kMinPassing = 20;  // 0.5 %
  std::mt19937_64 rng(1);
  const std::uint64_t n = scaled.points.size();
  int passing = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const int i1 = DrawIndex(rng, n), i2 = DrawIndex(rng, n), i3 = DrawIndex(rng, n);
    if (i1 == i2 || i1 == i3 || i2 == i3) continue;
    if (SquaredArea(scaled.points[i1], scaled.points[i2], scaled.points[i3]) > kMinSquaredArea) {
      ++passing;
    }
  }
  if (passing < kMinPassing) {
    result.reason = "only " + std::to_string(passing) + " of " + std::to_string(kTrials) +
                    " trial triples are non-degenerate triangles; PCL's ESF might not terminate";
    return result;
  }

  pcl::ESFEstimation<pcl::PointXYZ, pcl::ESFSignature640> esf;
  esf.setInputCloud(ToPclXYZ(cloud));
  pcl::PointCloud<pcl::ESFSignature640> output;
  esf.compute(output);
  if (output.size() != 1) {
    result.reason = "pcl::ESFEstimation returned no descriptor";
    return result;
  }
  for (int i = 0; i < 640; ++i) result.histogram[i] = output[0].histogram[i];
  if (!result.histogram.allFinite()) {
    result.histogram.setZero();
    result.reason = "pcl::ESFEstimation returned a non-finite histogram";
    return result;
  }
  result.ok = true;
  return result;
}

double ChiSquareDistance(const float* a, const float* b, int size) {
  double sum = 0.0;
  for (int i = 0; i < size; ++i) {
    const double s = static_cast<double>(a[i]) + static_cast<double>(b[i]);
    if (s > 0.0) {
      const double d = static_cast<double>(a[i]) - static_cast<double>(b[i]);
      sum += d * d / s;
    }
  }
  return sum;
}

}  // namespace uwscan::perception
