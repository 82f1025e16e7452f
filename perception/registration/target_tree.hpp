#pragma once

// The exact nearest-target-point search that ICP pairs with: FLANN kd-trees over the two halves of
// the target, built side by side. Included by icp.cpp and its test only (it brings FLANN's
// headers).

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/result_set.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "perception/cloud/nearest_grid.hpp"
#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

inline constexpr int kNoMatch = -1;

// The nearest point within a radius: a FLANN result set of capacity 1 that starts with the
// radius as its worst distance, so the tree prunes everything beyond it; of equally near points
// the lowest index wins (as in NearestGrid). It reports target indices: a tree over part of the
// target hands it its points' indices (SearchIn).
// With a normal gate, only points whose normal is within the gate's angle of the query's count.
class NearestWithin : public flann::ResultSet<float> {
 public:
  void Reset(float radius_sq) {
    worst_ = radius_sq;
    bound_ = radius_sq;
    index_ = kNoMatch;
  }
  // Candidates must have normals[index] . normal >= min_cos; normals == nullptr: no gate.
  void Gate(const std::vector<Eigen::Vector3f>* normals, const Eigen::Vector3f& normal,
            float min_cos) {
    normals_ = normals;
    normal_ = normal;
    min_cos_ = min_cos;
  }
  // The tree searched next numbers its points i for target point ids[i].
  void SearchIn(const std::uint32_t* ids) { ids_ = ids; }
  bool full() const override { return true; }
  // Whether target point `index` passes the gate.
  bool Accepts(std::size_t index) const {
    return normals_ == nullptr || (*normals_)[index].dot(normal_) >= min_cos_;
  }
  void addPoint(float dist, size_t index) override {
    const auto id = static_cast<int>(ids_[index]);
    const bool nearer = dist < worst_ || (dist == worst_ && index_ != kNoMatch && id < index_);
    if (nearer && Accepts(static_cast<std::size_t>(id))) {
      worst_ = dist;
      // FLANN hands over only points strictly nearer than worstDist(): a point as near as the
      // nearest found must reach addPoint too, so that of equally near points the lowest index
      // wins, whatever order the trees visit them in.
      bound_ = std::nextafter(dist, std::numeric_limits<float>::max());
      index_ = id;
    }
  }
  float worstDist() const override { return bound_; }
  int index() const { return index_; }

 private:
  float worst_ = 0.0f;  // the nearest distance found, or the radius
  float bound_ = 0.0f;  // what FLANN prunes with
  int index_ = kNoMatch;
  const std::uint32_t* ids_ = nullptr;
  const std::vector<Eigen::Vector3f>* normals_ = nullptr;
  Eigen::Vector3f normal_ = Eigen::Vector3f::Zero();
  float min_cos_ = -1.0f;
};

// Exact nearest-neighbour search on the target points (relative to the target origin), and for
// radii up to grid_radius_m (when > 0) a NearestGrid of cells of grid_cell_m (0: a quarter of the
// radius). The kd-tree is two: the target split at its median along its widest axis, one FLANN
// tree per half, built on two threads (building one tree is serial, and ICP builds one per
// registration). A query searches its own half, then the other only when the split plane is
// as near as the nearest point found: the same nearest point as a search of every point.
class TargetTree {
 public:
  TargetTree(const PointCloud& target, double grid_radius_m, double grid_cell_m, int threads);
  // Index of the nearest target point within `radius` of p, or kNoMatch. Thread-safe.
  int Nearest(const Eigen::Vector3d& p, float radius_sq, NearestWithin& result) const {
    const Eigen::Vector3f query = p.cast<float>();
    result.Reset(radius_sq);
    if (grid_ && radius_sq <= grid_radius_sq_) {
      return static_cast<int>(
          grid_->Nearest(query, radius_sq, [&](std::uint32_t j) { return result.Accepts(j); }));
    }
    const float beyond_split = query[axis_] - split_;
    const Half& near = beyond_split < 0.0f ? low_ : high_;
    const Half& far = beyond_split < 0.0f ? high_ : low_;
    near.Search(query, result);
    if (beyond_split * beyond_split < result.worstDist()) far.Search(query, result);
    return result.index();
  }
  const NearestGrid* grid() const { return grid_ ? &*grid_ : nullptr; }

 private:
  // Some of the target's points, their target indices and their tree.
  struct Half {
    explicit Half(std::vector<std::uint32_t> ids, const PointCloud& target);
    void Search(const Eigen::Vector3f& query, NearestWithin& result) const {
      result.SearchIn(ids.data());
      index.findNeighbors(result, query.data(), exact);
    }
    flann::SearchParams exact{-1, 0.0f};  // unlimited checks, eps = 0: exact
    std::vector<std::uint32_t> ids;
    std::vector<Eigen::Vector3f> points;
    flann::KDTreeSingleIndex<flann::L2_3D<float>> index;
  };
  // The target's point indices either side of its median along its widest axis.
  struct MedianSplit {
    int axis = 0;
    float value = 0.0f;
    std::vector<std::uint32_t> low, high;
  };
  static MedianSplit SplitAtMedian(const PointCloud& target);
  TargetTree(const PointCloud& target, MedianSplit split, double grid_radius_m, double grid_cell_m,
             int threads);

  int axis_;
  float split_;
  Half low_;   // coordinates along axis_ <= split_
  Half high_;  // >= split_
  std::optional<NearestGrid> grid_;
  float grid_radius_sq_ = 0.0f;
};

}  // namespace uwscan::perception
