#include "perception/cloud/nearest_grid.hpp"

#include <limits>
#include <string>
#include <utility>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

constexpr std::uint64_t kMaxCells = std::uint64_t{1} << 24;  // 84 MB of cell starts and rings

// One pass of the chessboard distance transform along a line of `count` values `stride` apart:
// each becomes min over the line's j of max(|i - j|, value[j]), looking at most `cap` cells away
// (values are capped at `cap`, so nothing farther can lower them).
void ChessboardPass(std::uint8_t* values, int count, std::ptrdiff_t stride, int cap,
                    std::vector<int>& line) {
  line.resize(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) line[static_cast<std::size_t>(i)] = values[i * stride];
  for (int i = 0; i < count; ++i) {
    int best = line[static_cast<std::size_t>(i)];
    for (int j = std::max(0, i - cap); j <= std::min(count - 1, i + cap); ++j) {
      best = std::min(best, std::max(std::abs(i - j), line[static_cast<std::size_t>(j)]));
    }
    values[i * stride] = static_cast<std::uint8_t>(best);
  }
}

// The points' lowest and highest coordinates; throws when a point is not finite.
std::pair<Eigen::Array3d, Eigen::Array3d> Bounds(std::span<const Eigen::Vector3f> points) {
  Eigen::Array3d lo_m = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity()),
                 hi_m = -lo_m;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) throw Error("NearestGrid: a point is not finite");
    lo_m = lo_m.min(p.cast<double>().array());
    hi_m = hi_m.max(p.cast<double>().array());
  }
  return {lo_m, hi_m};
}

}  // namespace

NearestGrid::NearestGrid(std::span<const Eigen::Vector3f> points, double cell_m,
                         double max_radius_m)
    : max_radius_m_(max_radius_m) {
  if (!(std::isfinite(cell_m) && cell_m > 0.0 && std::isfinite(max_radius_m) &&
        max_radius_m >= cell_m)) {
    throw Error("NearestGrid: need a finite cell_m > 0 and max_radius_m >= cell_m, got " +
                std::to_string(cell_m) + " and " + std::to_string(max_radius_m));
  }
  if (max_radius_m / cell_m > 200.0)
    throw Error("NearestGrid: max_radius_m is more than 200 cells");
  if (points.size() >= std::numeric_limits<std::uint32_t>::max())
    throw Error("NearestGrid: too many points");
  const auto [lo_m, hi_m] = Bounds(points);
  // Cells twice as wide until the grid fits its budget (a large object's model): the search
  // stays exact, only slower.
  Eigen::Array3d lo, hi;
  int margin = 0;
  for (;; cell_m *= 2.0) {
    inverse_cell_m_ = 1.0 / cell_m;
    max_rings_ = static_cast<int>(std::ceil(max_radius_m / cell_m));
    margin = max_rings_ + 1;
    if (points.empty()) break;
    lo = (lo_m * inverse_cell_m_).floor();
    hi = (hi_m * inverse_cell_m_).floor();
    if ((hi - lo + 1.0 + 2.0 * margin).prod() <= static_cast<double>(kMaxCells)) break;
  }
  cell_m_ = cell_m;
  if (points.empty()) return;
  if (!(lo.abs().maxCoeff() < 1e9 && hi.abs().maxCoeff() < 1e9)) {
    throw Error("NearestGrid: coordinates too large for cells of " + std::to_string(cell_m) + " m");
  }
  const Eigen::Array3d extent = hi - lo + 1.0 + 2.0 * margin;
  first_ = lo.cast<int>() - margin;
  n_ = extent.cast<int>();
  const std::uint64_t cells = static_cast<std::uint64_t>(n_.x()) *
                              static_cast<std::uint64_t>(n_.y()) *
                              static_cast<std::uint64_t>(n_.z());

  SortByCell(points, cells);
  MeasureEmptyRings(cells);
}

// Counting sort by cell: stable, so a cell's points keep increasing indices.
void NearestGrid::SortByCell(std::span<const Eigen::Vector3f> points, std::uint64_t cells) {
  std::vector<std::uint64_t> keys(points.size());
  cell_start_.assign(cells + 1, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Array3i c =
        (points[i].cast<double>().array() * inverse_cell_m_).floor().cast<int>() - first_;
    keys[i] = Key(c.x(), c.y(), c.z());
    ++cell_start_[keys[i] + 1];
  }
  for (std::uint64_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  std::vector<std::uint32_t> next(cell_start_.begin(), cell_start_.end() - 1);
  index_.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    index_[next[keys[i]]++] = static_cast<std::uint32_t>(i);
  x_.resize(points.size());
  y_.resize(points.size());
  z_.resize(points.size());
  for (std::size_t s = 0; s < index_.size(); ++s) {
    x_[s] = points[index_[s]].x();
    y_[s] = points[index_[s]].y();
    z_[s] = points[index_[s]].z();
  }
}

// Rings out to the nearest occupied cell: the chessboard distance transform of the occupied
// cells, separable into passes along z, y and x, capped past the rings any query looks at.
void NearestGrid::MeasureEmptyRings(std::uint64_t cells) {
  const int cap = max_rings_ + 1;
  empty_rings_.assign(cells, static_cast<std::uint8_t>(cap));
  for (std::uint64_t c = 0; c < cells; ++c) {
    if (cell_start_[c + 1] > cell_start_[c]) empty_rings_[c] = 0;
  }
  std::vector<int> line;
  const std::ptrdiff_t sz = 1, sy = n_.z(), sx = static_cast<std::ptrdiff_t>(n_.y()) * n_.z();
  for (int x = 0; x < n_.x(); ++x) {
    for (int y = 0; y < n_.y(); ++y)
      ChessboardPass(&empty_rings_[Key(x, y, 0)], n_.z(), sz, cap, line);
  }
  for (int x = 0; x < n_.x(); ++x) {
    for (int z = 0; z < n_.z(); ++z)
      ChessboardPass(&empty_rings_[Key(x, 0, z)], n_.y(), sy, cap, line);
  }
  for (int y = 0; y < n_.y(); ++y) {
    for (int z = 0; z < n_.z(); ++z)
      ChessboardPass(&empty_rings_[Key(0, y, z)], n_.x(), sx, cap, line);
  }
}

}  // namespace uwscan::perception
