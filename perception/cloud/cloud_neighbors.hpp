#pragma once

// Neighbour searches over the float points of a PointCloud (coordinates relative to its origin),
// shared by the preprocessing filters and FPFH. No FLANN or PCL types appear here.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace uwscan::perception {

// Fixed-radius neighbour search on a uniform grid of cubic cells about one radius wide: a query
// visits the 27 cells around it. A point p is a neighbour of q when the squared distance
// ((q.x-p.x)^2 + (q.y-p.y)^2) + (q.z-p.z)^2, evaluated in float in that order, is strictly below
// float(radius_m^2): the same test, to the bit, as FLANN's kd-tree radius search that PCL's
// KdTreeFLANN::radiusSearch uses, so both return the same neighbour sets.
// Neighbours come in a fixed order (by cell, then by index): deterministic, not sorted by
// distance. Queries are const and safe to run concurrently.
class RadiusGrid {
 public:
  // `points` must outlive the grid; radius_m must be finite and > 0 and the points finite.
  // Throws uwscan::Error if the cloud spans more than 2^21 cells along an axis (radius far too
  // small for the cloud's extent) or holds 2^32 points or more.
  RadiusGrid(std::span<const Eigen::Vector3f> points, double radius_m);

  // Replaces `indices` and `squared_distances_m2` with the neighbours of q (q itself included
  // when it is one of the points); none for a non-finite q.
  void Query(const Eigen::Vector3f& q, std::vector<std::uint32_t>& indices,
             std::vector<float>& squared_distances_m2) const;

  double radius_m() const { return radius_m_; }
  std::size_t size() const { return index_.size(); }

 private:
  // The constructor's steps: the block of cells the points occupy (throws when it is too wide),
  // each point's linear cell key, and the points' order sorted by key (the cell table filled).
  void SetExtent(std::span<const Eigen::Vector3f> points);
  std::vector<std::uint64_t> CellKeys(std::span<const Eigen::Vector3f> points) const;
  std::vector<std::uint32_t> SortByCell(const std::vector<std::uint64_t>& keys);
  // Range [begin, end) of sorted point positions of the cells with linear keys [key_lo, key_hi].
  void CellRange(std::uint64_t key_lo, std::uint64_t key_hi, std::uint32_t& begin,
                 std::uint32_t& end) const;

  double radius_m_ = 0.0;
  float radius_sq_ = 0.0f;       // float(radius_m^2), FLANN's threshold
  double inverse_cell_m_ = 0.0;  // 1 / cell size
  Eigen::Array3i min_cell_ = Eigen::Array3i::Zero();
  Eigen::Array3i num_cells_ = Eigen::Array3i::Zero();
  bool dense_ = true;
  std::vector<std::uint32_t> cell_start_;  // dense: per linear key (+1); sparse: per occupied cell
  std::vector<std::uint64_t> cell_keys_;   // sparse only: sorted linear keys of occupied cells
  std::vector<float> x_, y_, z_;           // points sorted by cell
  std::vector<std::uint32_t> index_;       // original index of each sorted point
};

// Exact k-nearest-neighbour search on a kd-tree (FLANN's single kd-tree, as PCL's KdTreeFLANN).
// Queries are const and safe to run concurrently.
class KnnIndex {
 public:
  // The points are copied; they must be finite. Throws uwscan::Error on 2^32 points or more.
  explicit KnnIndex(std::span<const Eigen::Vector3f> points);
  ~KnnIndex();
  KnnIndex(const KnnIndex&) = delete;
  KnnIndex& operator=(const KnnIndex&) = delete;

  // Replaces the outputs with the min(k, size()) points nearest to q, nearest first (q itself
  // included when it is one of the points), with their squared distances.
  void Query(const Eigen::Vector3f& q, int k, std::vector<std::uint32_t>& indices,
             std::vector<float>& squared_distances_m2) const;

  std::size_t size() const { return size_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::size_t size_ = 0;
};

}  // namespace uwscan::perception
