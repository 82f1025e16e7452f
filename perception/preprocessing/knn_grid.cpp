#include "perception/preprocessing/knn_grid.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/flann_distance.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/parallel_tasks.hpp"

namespace uwscan::perception {
namespace {

constexpr double kMaxCellCoordinate = 1099511627776.0;  // 2^40: keys and key +- 1 stay exact
constexpr std::ptrdiff_t kCellsPerTask = 64;
constexpr int kMaxRing = 2;  // blocks of 3^3, then 5^3 cells; beyond, every point or a kd-tree
constexpr std::size_t kMostQueriesWithoutTree = 64;

// The k best (distance, index) pairs seen so far, nearer first, then lower index: each packed
// into one integer, the distance's bits above the index (for non-negative floats the bits order
// as the values), so a pair is ranked by a single comparison.
class NearestK {
 public:
  void Reset(std::size_t k) {
    k_ = k;
    size_ = 0;
    keys_.resize(k);
    indices_.resize(k);
  }
  bool Full() const { return size_ == k_; }
  float Worst() const {
    return std::bit_cast<float>(static_cast<std::uint32_t>(keys_[k_ - 1] >> 32));
  }
  // A candidate at squared distance d (>= 0, never -0), kept when it ranks before the worst kept.
  void Offer(float d, std::uint32_t index) {
    const std::uint64_t key = (std::uint64_t{std::bit_cast<std::uint32_t>(d)} << 32) | index;
    if (size_ == k_ && key >= keys_[k_ - 1]) return;
    std::size_t at = size_ == k_ ? k_ - 1 : size_++;
    for (; at > 0 && key < keys_[at - 1]; --at) keys_[at] = keys_[at - 1];
    keys_[at] = key;
  }
  std::span<const std::uint32_t> Indices() {
    for (std::size_t i = 0; i < size_; ++i) indices_[i] = static_cast<std::uint32_t>(keys_[i]);
    return {indices_.data(), size_};
  }

 private:
  std::size_t k_ = 0, size_ = 0;
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> indices_;
};

// The cells of a block `ring` cells out each way, its centre first, then by distance from it:
// near points are offered first, so the k nearest fill early and most farther points are turned
// away at a glance.
using CellOffsets = std::vector<std::array<std::int64_t, 3>>;
CellOffsets BlockOffsets(std::int64_t ring) {
  CellOffsets offsets;
  for (std::int64_t dx = -ring; dx <= ring; ++dx) {
    for (std::int64_t dy = -ring; dy <= ring; ++dy) {
      for (std::int64_t dz = -ring; dz <= ring; ++dz) offsets.push_back({dx, dy, dz});
    }
  }
  std::stable_sort(offsets.begin(), offsets.end(), [](const auto& a, const auto& b) {
    return a[0] * a[0] + a[1] * a[1] + a[2] * a[2] < b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
  });
  return offsets;
}

VoxelKey CellOf(const Eigen::Vector3f& p, double inverse_cell) {
  VoxelKey key;
  for (int a = 0; a < 3; ++a) {
    key[static_cast<std::size_t>(a)] =
        static_cast<std::int64_t>(std::floor(static_cast<double>(p[a]) * inverse_cell));
  }
  return key;
}

// FLANN's neighbours (nearest first) with equally near ones put in index order, as on the grid.
void SortTies(std::vector<std::uint32_t>& indices, const std::vector<float>& distances) {
  for (std::size_t i = 1; i < indices.size(); ++i) {
    for (std::size_t j = i;
         j > 0 && distances[j] == distances[j - 1] && indices[j] < indices[j - 1]; --j) {
      std::swap(indices[j], indices[j - 1]);
    }
  }
}

}  // namespace

struct KnnGrid::Scratch {
  std::vector<float> x, y, z, distances;  // the block's points
  std::vector<std::uint32_t> index;
  NearestK nearest;
  std::vector<std::uint32_t> pending;  // sorted positions of the cell's points not yet visited
};

KnnGrid::KnnGrid(std::span<const Eigen::Vector3f> points, double cell_m)
    : points_(points), cell_m_(cell_m) {
  if (!(std::isfinite(cell_m) && cell_m > 0.0)) {
    throw Error("KnnGrid: cell_m must be finite and > 0, got " + std::to_string(cell_m));
  }
  if (points.size() >= std::numeric_limits<std::uint32_t>::max())
    throw Error("KnnGrid: " + std::to_string(points.size()) + " points; at most 2^32 - 2");
  const double inverse_cell = 1.0 / cell_m;
  std::vector<std::uint32_t> cell_of(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Array3d scaled = points[i].cast<double>().array() * inverse_cell;
    if (!(scaled.abs() < kMaxCellCoordinate).all()) {
      throw Error("KnnGrid: point " + std::to_string(i) +
                  " is not finite or more than 2^40 cells from the origin");
    }
    cell_of[i] = cells_.Insert(CellOf(points[i], inverse_cell));
  }
  // Counting sort by cell: stable, so a cell's points keep increasing indices.
  cell_start_.assign(cells_.size() + 1, 0);
  for (std::uint32_t c : cell_of) ++cell_start_[c + 1];
  for (std::size_t c = 0; c < cells_.size(); ++c) cell_start_[c + 1] += cell_start_[c];
  std::vector<std::uint32_t> next(cell_start_.begin(), cell_start_.end() - 1);
  index_.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    index_[next[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  x_.resize(points.size());
  y_.resize(points.size());
  z_.resize(points.size());
  for (std::size_t s = 0; s < points.size(); ++s) {
    x_[s] = points[index_[s]].x();
    y_[s] = points[index_[s]].y();
    z_[s] = points[index_[s]].z();
  }
}

void KnnGrid::GatherBlock(std::uint32_t cell, int ring, Scratch& scratch) const {
  static const std::array<CellOffsets, kMaxRing + 1> kOffsets = {CellOffsets{}, BlockOffsets(1),
                                                                 BlockOffsets(2)};
  scratch.x.clear();
  scratch.y.clear();
  scratch.z.clear();
  scratch.index.clear();
  const VoxelKey& centre = cells_.key(cell);
  for (const std::array<std::int64_t, 3>& d : kOffsets[static_cast<std::size_t>(ring)]) {
    const std::int64_t found = cells_.Find({centre[0] + d[0], centre[1] + d[1], centre[2] + d[2]});
    if (found < 0) continue;
    const std::size_t c = static_cast<std::size_t>(found);
    for (std::uint32_t s = cell_start_[c]; s < cell_start_[c + 1]; ++s) {
      scratch.x.push_back(x_[s]);
      scratch.y.push_back(y_[s]);
      scratch.z.push_back(z_[s]);
      scratch.index.push_back(index_[s]);
    }
  }
}

bool KnnGrid::NearestInBlock(std::uint32_t s, std::uint32_t cell, int ring, std::size_t k,
                             Scratch& scratch) const {
  const float qx = x_[s], qy = y_[s], qz = z_[s];
  const std::size_t count = scratch.x.size();
  scratch.distances.resize(count);
  for (std::size_t j = 0; j < count; ++j) {
    scratch.distances[j] =
        FlannSquaredDistance(qx, qy, qz, scratch.x[j], scratch.y[j], scratch.z[j]);
  }
  scratch.nearest.Reset(k);
  for (std::size_t j = 0; j < count; ++j) {
    const float d = scratch.distances[j];
    if (scratch.nearest.Full() && d > scratch.nearest.Worst()) continue;
    scratch.nearest.Offer(d, scratch.index[j]);
  }
  if (count == points_.size()) return true;  // the block holds the whole cloud
  if (!scratch.nearest.Full()) return false;
  // A point outside the block is at least as far as the block's nearest face. Float distances
  // are within a few 1e-7 of the exact ones: the margin of 1e-5 keeps the test strict.
  const VoxelKey& centre = cells_.key(cell);
  const double q[3] = {qx, qy, qz};
  double face_m = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < 3; ++a) {
    const double lo = static_cast<double>(centre[a] - ring) * cell_m_;
    const double hi = static_cast<double>(centre[a] + ring + 1) * cell_m_;
    face_m = std::min({face_m, q[a] - lo, hi - q[a]});
  }
  return static_cast<double>(scratch.nearest.Worst()) < face_m * face_m * (1.0 - 1e-5);
}

void KnnGrid::VisitCell(std::uint32_t cell, std::size_t k, Scratch& scratch, const Visit& visit,
                        std::vector<std::uint32_t>& uncertain) const {
  scratch.pending.clear();
  for (std::uint32_t s = cell_start_[cell]; s < cell_start_[cell + 1]; ++s)
    scratch.pending.push_back(s);
  for (int ring = 1; ring <= kMaxRing && !scratch.pending.empty(); ++ring) {
    GatherBlock(cell, ring, scratch);
    std::size_t still = 0;
    for (std::uint32_t s : scratch.pending) {
      if (NearestInBlock(s, cell, ring, k, scratch)) {
        visit(index_[s], scratch.nearest.Indices());
      } else {
        scratch.pending[still++] = s;
      }
    }
    scratch.pending.resize(still);
  }
  for (std::uint32_t s : scratch.pending) uncertain.push_back(index_[s]);
}

void KnnGrid::ForEachPoint(int k, int threads, const Visit& visit) const {
  if (k < 1) throw Error("KnnGrid: k must be at least 1, got " + std::to_string(k));
  if (points_.empty()) return;
  const std::size_t count = std::min(static_cast<std::size_t>(k), points_.size());
  const std::ptrdiff_t num_cells = static_cast<std::ptrdiff_t>(cells_.size());
  const std::ptrdiff_t tasks = (num_cells + kCellsPerTask - 1) / kCellsPerTask;
  std::vector<std::vector<std::uint32_t>> uncertain(static_cast<std::size_t>(tasks));
  RunParallelTasks(tasks, threads, [&](std::ptrdiff_t task) {
    Scratch scratch;
    const std::ptrdiff_t end = std::min(num_cells, (task + 1) * kCellsPerTask);
    for (std::ptrdiff_t c = task * kCellsPerTask; c < end; ++c) {
      VisitCell(static_cast<std::uint32_t>(c), count, scratch, visit,
                uncertain[static_cast<std::size_t>(task)]);
    }
  });
  std::vector<std::uint32_t> rest;
  for (const std::vector<std::uint32_t>& part : uncertain) {
    rest.insert(rest.end(), part.begin(), part.end());
  }
  SearchTheRest(rest, count, threads, visit);
}

void KnnGrid::SearchTheRest(const std::vector<std::uint32_t>& rest, std::size_t k, int threads,
                            const Visit& visit) const {
  if (rest.empty()) return;
  // A kd-tree costs about 60 distances per point to build: for a few queries, look at every point.
  if (rest.size() <= kMostQueriesWithoutTree) {
    RunParallelTasks(std::ssize(rest), threads, [&](std::ptrdiff_t r) {
      thread_local NearestK nearest;
      const Eigen::Vector3f& q = points_[rest[static_cast<std::size_t>(r)]];
      nearest.Reset(k);
      for (std::size_t s = 0; s < index_.size(); ++s) {
        const float d = FlannSquaredDistance(q.x(), q.y(), q.z(), x_[s], y_[s], z_[s]);
        if (nearest.Full() && d > nearest.Worst()) continue;
        nearest.Offer(d, index_[s]);
      }
      visit(rest[static_cast<std::size_t>(r)], nearest.Indices());
    });
    return;
  }
  const KnnIndex tree(points_);
  RunParallelTasks(std::ssize(rest), threads, [&](std::ptrdiff_t r) {
    thread_local std::vector<std::uint32_t> indices;
    thread_local std::vector<float> distances;
    const std::uint32_t point = rest[static_cast<std::size_t>(r)];
    tree.Query(points_[point], static_cast<int>(k), indices, distances);
    SortTies(indices, distances);
    visit(point, indices);
  });
}

}  // namespace uwscan::perception
