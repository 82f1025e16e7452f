#pragma once

// The k nearest neighbours of every point of a cloud at once, cell by cell on a hashed grid: the
// search behind the normals of a voxelised cloud (a submap), where FLANN's kd-tree queries cost
// several times more than the fit they feed.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "perception/preprocessing/voxel_index.hpp"

namespace uwscan::perception {

// The points grouped into cubic cells of a grid hashed by VoxelIndex (only occupied cells are
// stored, whatever the cloud's extent). The points of one cell share their candidates: the points
// of the 3 x 3 x 3 cells around it, gathered once. A point's k nearest candidates are its k
// nearest in the cloud when the k-th is nearer than the block's nearest face; the points where
// it is not (a sparse or isolated part, a cloud's rim) are searched on FLANN's kd-tree, built only
// when there are such points. Fastest when a cell is about as wide as the k-th neighbour's
// distance (a surface voxelised at v, k = 15: about 3 v).
// Distances are FLANN's squared L2 (FlannSquaredDistance), so the neighbours are those KnnIndex
// finds, nearest first; of equally near points the lower index comes first (on the kd-tree,
// which of several points tied at the k-th distance is taken is FLANN's choice).
class KnnGrid {
 public:
  // `points` must outlive the grid and be finite; cell_m finite and > 0. Throws uwscan::Error
  // otherwise, when a coordinate is beyond 2^40 cells, or on 2^32 - 1 points or more.
  KnnGrid(std::span<const Eigen::Vector3f> points, double cell_m);

  // neighbours: the min(k, size()) points nearest to `point` (itself included), nearest first.
  using Visit = std::function<void(std::size_t point, std::span<const std::uint32_t> neighbours)>;
  // Calls visit once for every point, on `threads` OpenMP threads (0: OpenMP's default), in no
  // fixed order: visit must write only what belongs to its point. An exception it throws is
  // rethrown here. k >= 1, else uwscan::Error.
  void ForEachPoint(int k, int threads, const Visit& visit) const;

  std::size_t size() const { return points_.size(); }

 private:
  struct Scratch;
  // Hands every point of `cell` to visit with its k nearest, found in the block one cell out or
  // else two; the points neither certifies are appended to `uncertain`.
  void VisitCell(std::uint32_t cell, std::size_t k, Scratch& scratch, const Visit& visit,
                 std::vector<std::uint32_t>& uncertain) const;
  // The k nearest of each point in `rest` among all points: by looking at every one for a few
  // points, else on FLANN's kd-tree.
  void SearchTheRest(const std::vector<std::uint32_t>& rest, std::size_t k, int threads,
                     const Visit& visit) const;
  // The points of the cells up to `ring` cells from `cell` along each axis, nearest cells first.
  void GatherBlock(std::uint32_t cell, int ring, Scratch& scratch) const;
  // The k nearest in the gathered block of the point at sorted position s (into
  // scratch.nearest); whether they are certainly its k nearest in the cloud.
  bool NearestInBlock(std::uint32_t s, std::uint32_t cell, int ring, std::size_t k,
                      Scratch& scratch) const;

  std::span<const Eigen::Vector3f> points_;
  double cell_m_ = 0.0;
  VoxelIndex cells_;
  std::vector<std::uint32_t> cell_start_;  // per cell id (+1): its points' sorted positions
  std::vector<float> x_, y_, z_;           // points sorted by cell
  std::vector<std::uint32_t> index_;       // original index of each sorted point
};

}  // namespace uwscan::perception
