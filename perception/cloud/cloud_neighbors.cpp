#include "perception/cloud/cloud_neighbors.hpp"

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "perception/cloud/flann_distance.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

constexpr std::int64_t kMaxCellsPerAxis = std::int64_t{1} << 21;

void RequireIndexable(std::size_t size, const char* what) {
  if (size >= std::numeric_limits<std::uint32_t>::max()) {
    throw Error(std::string(what) + ": " + std::to_string(size) +
                " points; at most 2^32 - 1 are supported");
  }
}

}  // namespace

RadiusGrid::RadiusGrid(std::span<const Eigen::Vector3f> points, double radius_m)
    : radius_m_(radius_m) {
  if (!(std::isfinite(radius_m) && radius_m > 0.0)) {
    throw Error("RadiusGrid: radius_m must be finite and > 0, got " + std::to_string(radius_m));
  }
  RequireIndexable(points.size(), "RadiusGrid");
  radius_sq_ = static_cast<float>(radius_m * radius_m);
  // Cells slightly wider than the radius, so rounding in floor(x / cell) can never put two
  // points closer than the radius more than one cell apart.
  inverse_cell_m_ = 1.0 / (radius_m * (1.0 + 1e-6));
  if (points.empty()) {
    cell_start_.assign(1, 0);
    return;
  }

  SetExtent(points);
  std::vector<std::uint32_t> order = SortByCell(CellKeys(points));
  // Structure of arrays in cell order: a query's distances read three contiguous runs.
  x_.resize(points.size());
  y_.resize(points.size());
  z_.resize(points.size());
  for (std::size_t s = 0; s < order.size(); ++s) {
    const Eigen::Vector3f& p = points[order[s]];
    x_[s] = p.x();
    y_[s] = p.y();
    z_[s] = p.z();
  }
  index_ = std::move(order);
}

void RadiusGrid::SetExtent(std::span<const Eigen::Vector3f> points) {
  Eigen::Array<double, 3, 1> lo =
      Eigen::Array<double, 3, 1>::Constant(std::numeric_limits<double>::infinity());
  Eigen::Array<double, 3, 1> hi = -lo;
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Array<double, 3, 1> c = (p.cast<double>().array() * inverse_cell_m_).floor();
    lo = lo.min(c);
    hi = hi.max(c);
  }
  const Eigen::Array<double, 3, 1> extent = hi - lo + 1.0;
  if (!(lo.abs().maxCoeff() < 1e9 && hi.abs().maxCoeff() < 1e9 &&
        extent.maxCoeff() <= static_cast<double>(kMaxCellsPerAxis))) {
    throw Error("RadiusGrid: radius " + std::to_string(radius_m_) +
                " m is too small for the cloud's extent (more than 2^21 cells along an axis)");
  }
  min_cell_ = lo.cast<int>();
  num_cells_ = extent.cast<int>();
}

std::vector<std::uint64_t> RadiusGrid::CellKeys(std::span<const Eigen::Vector3f> points) const {
  const std::uint64_t ny = static_cast<std::uint64_t>(num_cells_.y());
  const std::uint64_t nz = static_cast<std::uint64_t>(num_cells_.z());
  std::vector<std::uint64_t> keys(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Array3i c =
        (points[i].cast<double>().array() * inverse_cell_m_).floor().cast<int>() - min_cell_;
    keys[i] = (static_cast<std::uint64_t>(c.x()) * ny + static_cast<std::uint64_t>(c.y())) * nz +
              static_cast<std::uint64_t>(c.z());
  }
  return keys;
}

std::vector<std::uint32_t> RadiusGrid::SortByCell(const std::vector<std::uint64_t>& keys) {
  const std::size_t n = keys.size();
  const std::uint64_t total_cells = static_cast<std::uint64_t>(num_cells_.x()) *
                                    static_cast<std::uint64_t>(num_cells_.y()) *
                                    static_cast<std::uint64_t>(num_cells_.z());
  std::vector<std::uint32_t> order(n);
  dense_ = total_cells <= std::max<std::uint64_t>(8 * n, 4096);
  if (dense_) {
    // Counting sort by key: stable, so points of a cell keep increasing indices.
    cell_start_.assign(total_cells + 1, 0);
    for (std::uint64_t key : keys) ++cell_start_[key + 1];
    for (std::uint64_t c = 0; c < total_cells; ++c) cell_start_[c + 1] += cell_start_[c];
    std::vector<std::uint32_t> next(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order[next[keys[i]]++] = static_cast<std::uint32_t>(i);
    return order;
  }
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(i);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return keys[a] != keys[b] ? keys[a] < keys[b] : a < b;
  });
  for (std::size_t s = 0; s < n; ++s) {
    const std::uint64_t key = keys[order[s]];
    if (cell_keys_.empty() || cell_keys_.back() != key) {
      cell_keys_.push_back(key);
      cell_start_.push_back(static_cast<std::uint32_t>(s));
    }
  }
  cell_start_.push_back(static_cast<std::uint32_t>(n));
  return order;
}

void RadiusGrid::CellRange(std::uint64_t key_lo, std::uint64_t key_hi, std::uint32_t& begin,
                           std::uint32_t& end) const {
  if (dense_) {
    begin = cell_start_[key_lo];
    end = cell_start_[key_hi + 1];
    return;
  }
  const auto first = std::lower_bound(cell_keys_.begin(), cell_keys_.end(), key_lo);
  const auto last = std::upper_bound(first, cell_keys_.end(), key_hi);
  begin = cell_start_[static_cast<std::size_t>(first - cell_keys_.begin())];
  end = cell_start_[static_cast<std::size_t>(last - cell_keys_.begin())];
}

void RadiusGrid::Query(const Eigen::Vector3f& q, std::vector<std::uint32_t>& indices,
                       std::vector<float>& squared_distances_m2) const {
  indices.clear();
  squared_distances_m2.clear();
  if (index_.empty() || !q.allFinite()) return;
  const Eigen::Array<double, 3, 1> c =
      (q.cast<double>().array() * inverse_cell_m_).floor() - min_cell_.cast<double>();
  const Eigen::Array<double, 3, 1> n = num_cells_.cast<double>();
  // Outside the occupied block by more than one cell: nothing within the radius.
  if ((c < -1.0).any() || (c > n).any()) return;
  const Eigen::Array3i ci = c.cast<int>();
  const int z_lo = std::max(ci.z() - 1, 0);
  const int z_hi = std::min(ci.z() + 1, num_cells_.z() - 1);
  if (z_lo > z_hi) return;
  const std::uint64_t ny = static_cast<std::uint64_t>(num_cells_.y());
  const std::uint64_t nz = static_cast<std::uint64_t>(num_cells_.z());
  std::array<std::pair<std::uint32_t, std::uint32_t>, 9> columns;  // sorted positions [begin, end)
  std::size_t column_count = 0, candidates = 0;
  for (int x = std::max(ci.x() - 1, 0); x <= std::min(ci.x() + 1, num_cells_.x() - 1); ++x) {
    for (int y = std::max(ci.y() - 1, 0); y <= std::min(ci.y() + 1, num_cells_.y() - 1); ++y) {
      const std::uint64_t column =
          (static_cast<std::uint64_t>(x) * ny + static_cast<std::uint64_t>(y)) * nz;
      auto& [begin, end] = columns[column_count++];
      CellRange(column + static_cast<std::uint64_t>(z_lo),
                column + static_cast<std::uint64_t>(z_hi), begin, end);
      candidates += end - begin;
    }
  }
  // Every candidate is written and the count moves on only past those within the radius: no
  // branch, which on a surface would be taken about half the time, unpredictably.
  indices.resize(candidates);
  squared_distances_m2.resize(candidates);
  const float qx = q.x(), qy = q.y(), qz = q.z();
  std::size_t count = 0;
  for (std::size_t c = 0; c < column_count; ++c) {
    for (std::uint32_t s = columns[c].first; s < columns[c].second; ++s) {
      const float d = FlannSquaredDistance(qx, qy, qz, x_[s], y_[s], z_[s]);
      indices[count] = index_[s];
      squared_distances_m2[count] = d;
      count += d < radius_sq_ ? 1 : 0;
    }
  }
  indices.resize(count);
  squared_distances_m2.resize(count);
}

struct KnnIndex::Impl {
  std::vector<float> data;  // row-major copy handed to FLANN
  std::unique_ptr<flann::KDTreeSingleIndex<flann::L2_Simple<float>>> index;
};

KnnIndex::KnnIndex(std::span<const Eigen::Vector3f> points)
    : impl_(std::make_unique<Impl>()), size_(points.size()) {
  RequireIndexable(points.size(), "KnnIndex");
  if (points.empty()) return;
  impl_->data.resize(3 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    impl_->data[3 * i] = points[i].x();
    impl_->data[3 * i + 1] = points[i].y();
    impl_->data[3 * i + 2] = points[i].z();
  }
  // Leaf size 15 as PCL's KdTreeFLANN.
  impl_->index = std::make_unique<flann::KDTreeSingleIndex<flann::L2_Simple<float>>>(
      flann::Matrix<float>(impl_->data.data(), points.size(), 3),
      flann::KDTreeSingleIndexParams(15));
  impl_->index->buildIndex();
}

KnnIndex::~KnnIndex() = default;

void KnnIndex::Query(const Eigen::Vector3f& q, int k, std::vector<std::uint32_t>& indices,
                     std::vector<float>& squared_distances_m2) const {
  indices.clear();
  squared_distances_m2.clear();
  if (size_ == 0 || k <= 0) return;
  const std::size_t count = std::min(static_cast<std::size_t>(k), size_);
  flann::KNNSimpleResultSet<float> result(count);
  impl_->index->findNeighbors(result, q.data(), flann::SearchParams(-1, 0.0f, true));
  std::vector<std::size_t> found(count);
  squared_distances_m2.resize(count);
  result.copy(found.data(), squared_distances_m2.data(), count, true);
  indices.resize(count);
  for (std::size_t i = 0; i < count; ++i) indices[i] = static_cast<std::uint32_t>(found[i]);
}

}  // namespace uwscan::perception
