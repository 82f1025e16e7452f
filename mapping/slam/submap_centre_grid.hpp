#pragma once

// Where the submaps' centres lie in the world, hashed into cubic cells: the loop search asks the
// cells around a place, in time that does not grow with the dive, where scanning every earlier
// submap's centre grew with it (bench/slam/RESULTS.md, "The loop search, late in a long dive").

#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace uwscan::mapping {

class SubmapCentreGrid {
 public:
  // cell_m: the cells' edge (m, > 0); a query costs a visit per cell its box touches.
  explicit SubmapCentreGrid(double cell_m);

  // Holds submap `index` (>= 0) at centre_W, moving it there when it is held already.
  void Place(int index, const Eigen::Vector3d& centre_W);

  // Every held submap whose centre lies within radius_m of centre_W, with others from the same
  // cells, in ascending index order. The caller measures the distance itself.
  std::vector<int> Near(const Eigen::Vector3d& centre_W, double radius_m) const;

  // How many submaps are held (indices 0 to held() - 1 when they are placed in order).
  int held() const { return held_; }

 private:
  using Key = std::uint64_t;
  Key KeyOf(const Eigen::Vector3d& p_W) const;
  Key KeyOfCell(std::int64_t x, std::int64_t y, std::int64_t z) const;

  double cell_m_;
  std::unordered_map<Key, std::vector<int>> cells_;
  std::vector<Key> key_of_;    // per index, where it is held
  std::vector<bool> is_held_;  // per index
  int held_ = 0;
};

}  // namespace uwscan::mapping
