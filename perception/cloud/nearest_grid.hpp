#pragma once

// Exact nearest point within a radius, searched ring by ring on a grid of small cells: the ICP's
// nearest-neighbour search on an object model, where FLANN's kd-tree spends most of its time.

#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "perception/cloud/flann_distance.hpp"

namespace uwscan::perception {

// A uniform grid of cubic cells (a few times smaller than the search radius) holding a cloud's
// points. A query visits rings of cells outwards from its own and stops as soon as no point of
// an unvisited ring can be nearer than the nearest found: near a surface sampled about a cell
// apart it looks at a few dozen points, whatever the radius. Each cell also stores how many
// rings out the nearest occupied cell is, so empty rings are skipped and a query farther than
// the radius from every point is answered at once.
// Distances are FLANN's squared L2 ((dx^2 + dy^2) + dz^2 in float, the kd-tree's own order), a
// point counts when strictly nearer than the radius, and of equally near points the lowest index
// wins. Queries are const and safe to run concurrently.
class NearestGrid {
 public:
  // Copies the points (finite). cell_m > 0; queries may use any radius up to max_radius_m
  // (>= cell_m, at most 200 cells). Cells are made twice as wide, as often as it takes, to keep
  // the grid within 2^24 cells. Throws uwscan::Error on invalid sizes or non-finite points.
  NearestGrid(std::span<const Eigen::Vector3f> points, double cell_m, double max_radius_m);

  // The nearest point to q strictly within sqrt(radius_sq_m2) (at most max_radius_m) among those
  // whose index passes accept(index), or -1 when there is none (or q is not finite).
  template <typename Accept>
  std::int64_t Nearest(const Eigen::Vector3f& q, float radius_sq_m2, Accept&& accept) const;
  // The same over every point.
  std::int64_t Nearest(const Eigen::Vector3f& q, float radius_sq_m2) const {
    return Nearest(q, radius_sq_m2, [](std::size_t) { return true; });
  }

  double max_radius_m() const { return max_radius_m_; }

 private:
  // The constructor's steps, once the grid's extent is set.
  void SortByCell(std::span<const Eigen::Vector3f> points, std::uint64_t cells);
  void MeasureEmptyRings(std::uint64_t cells);
  std::uint64_t Key(int x, int y, int z) const {
    return (static_cast<std::uint64_t>(x) * static_cast<std::uint64_t>(n_.y()) +
            static_cast<std::uint64_t>(y)) *
               static_cast<std::uint64_t>(n_.z()) +
           static_cast<std::uint64_t>(z);
  }

  double cell_m_ = 0.0, inverse_cell_m_ = 0.0, max_radius_m_ = 0.0;
  int max_rings_ = 0;                              // rings that cover max_radius_m
  Eigen::Array3i first_ = Eigen::Array3i::Zero();  // cell coordinates of the grid's corner cell
  Eigen::Array3i n_ = Eigen::Array3i::Zero();      // cells along each axis
  std::vector<std::uint32_t> cell_start_;          // per cell (+1): its points' sorted positions
  std::vector<std::uint8_t> empty_rings_;  // per cell: rings out to an occupied cell (capped)
  std::vector<float> x_, y_, z_;           // points sorted by cell
  std::vector<std::uint32_t> index_;       // original index of each sorted point
};

template <typename Accept>
std::int64_t NearestGrid::Nearest(const Eigen::Vector3f& q, float radius_sq_m2,
                                  Accept&& accept) const {
  assert(std::sqrt(static_cast<double>(radius_sq_m2)) <= max_radius_m_ * (1.0 + 1e-6));
  if (index_.empty() || !q.allFinite()) return -1;
  const Eigen::Array<double, 3, 1> scaled = q.cast<double>().array() * inverse_cell_m_;
  const Eigen::Array<double, 3, 1> floor = scaled.floor();
  const Eigen::Array<double, 3, 1> c = floor - first_.cast<double>();
  // The grid reaches max_rings_ + 1 cells past every point: a query outside it is too far.
  if ((c < 0.0).any() || (c >= n_.cast<double>()).any()) return -1;
  const Eigen::Array3i ci = c.cast<int>();
  // A point k >= 1 rings out is at least (k - 1) cells plus the query's distance to the nearest
  // face of its own cell away; shrunk by a hair for float rounding of the distances.
  const Eigen::Array<double, 3, 1> frac = scaled - floor;
  const double face_m = std::min(frac.min(1.0 - frac).minCoeff(), 1.0) * cell_m_;
  const double radius_m = std::sqrt(static_cast<double>(radius_sq_m2));
  auto ring_bound_m = [&](int k) {
    return k == 0 ? 0.0 : (k - 1) * cell_m_ + face_m - 1e-5 * cell_m_;
  };
  const int first_ring = empty_rings_[Key(ci.x(), ci.y(), ci.z())];
  float best = radius_sq_m2;
  std::int64_t found = -1;
  const float qx = q.x(), qy = q.y(), qz = q.z();
  auto visit = [&](std::uint64_t key_lo, std::uint64_t key_hi) {
    for (std::uint32_t s = cell_start_[key_lo]; s < cell_start_[key_hi + 1]; ++s) {
      const float d = FlannSquaredDistance(qx, qy, qz, x_[s], y_[s], z_[s]);
      if (d > best || (d == best && (found < 0 || index_[s] > found))) continue;
      if (accept(index_[s])) {
        best = d;
        found = index_[s];
      }
    }
  };
  for (int k = first_ring; k <= max_rings_; ++k) {
    const double bound_m = ring_bound_m(k);
    if (bound_m >= radius_m || (found >= 0 && bound_m * bound_m > static_cast<double>(best))) break;
    const int x_lo = std::max(ci.x() - k, 0), x_hi = std::min(ci.x() + k, n_.x() - 1);
    const int y_lo = std::max(ci.y() - k, 0), y_hi = std::min(ci.y() + k, n_.y() - 1);
    const int z_lo = std::max(ci.z() - k, 0), z_hi = std::min(ci.z() + k, n_.z() - 1);
    for (int x = x_lo; x <= x_hi; ++x) {
      for (int y = y_lo; y <= y_hi; ++y) {
        if (std::abs(x - ci.x()) == k || std::abs(y - ci.y()) == k) {
          visit(Key(x, y, z_lo), Key(x, y, z_hi));  // the ring's face: the whole column
        } else {
          if (ci.z() - k >= 0) visit(Key(x, y, ci.z() - k), Key(x, y, ci.z() - k));
          if (k > 0 && ci.z() + k < n_.z()) visit(Key(x, y, ci.z() + k), Key(x, y, ci.z() + k));
        }
      }
    }
  }
  return found;
}

}  // namespace uwscan::perception
