#include "mapping/slam/submap_centre_grid.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// Cell coordinates take 21 bits each: +-2^20 cells, over a thousand kilometres at a metre a cell.
// Beyond that they are held at the edge, where a query of the same place finds them.
constexpr std::int64_t kCellLimit = (std::int64_t{1} << 20) - 1;

std::int64_t CellCoordinate(double value_m, double cell_m) {
  const auto limit = static_cast<double>(kCellLimit);
  return static_cast<std::int64_t>(std::clamp(std::floor(value_m / cell_m), -limit, limit));
}

}  // namespace

SubmapCentreGrid::SubmapCentreGrid(double cell_m) : cell_m_(cell_m) {
  if (!(cell_m > 0.0) || !std::isfinite(cell_m))
    throw Error("submap centre grid: cell size " + std::to_string(cell_m) + " m is not positive");
}

SubmapCentreGrid::Key SubmapCentreGrid::KeyOfCell(std::int64_t x, std::int64_t y,
                                                  std::int64_t z) const {
  const auto field = [](std::int64_t c) { return static_cast<Key>(c + kCellLimit) & 0x1fffffu; };
  return (field(x) << 42) | (field(y) << 21) | field(z);
}

SubmapCentreGrid::Key SubmapCentreGrid::KeyOf(const Eigen::Vector3d& p_W) const {
  return KeyOfCell(CellCoordinate(p_W.x(), cell_m_), CellCoordinate(p_W.y(), cell_m_),
                   CellCoordinate(p_W.z(), cell_m_));
}

void SubmapCentreGrid::Place(int index, const Eigen::Vector3d& centre_W) {
  if (index < 0) throw Error("submap centre grid: negative submap index " + std::to_string(index));
  if (!centre_W.allFinite()) {
    throw Error("submap centre grid: submap " + std::to_string(index) +
                "'s centre is not finite (NaN or infinite pose)");
  }
  const auto i = static_cast<std::size_t>(index);
  if (i >= key_of_.size()) {
    key_of_.resize(i + 1, 0);
    is_held_.resize(i + 1, false);
  }
  const Key key = KeyOf(centre_W);
  if (is_held_[i]) {
    if (key_of_[i] == key) return;
    std::vector<int>& old_cell = cells_[key_of_[i]];
    old_cell.erase(std::find(old_cell.begin(), old_cell.end(), index));
    if (old_cell.empty()) cells_.erase(key_of_[i]);
  } else {
    is_held_[i] = true;
    ++held_;
  }
  key_of_[i] = key;
  cells_[key].push_back(index);
}

std::vector<int> SubmapCentreGrid::Near(const Eigen::Vector3d& centre_W, double radius_m) const {
  if (!centre_W.allFinite() || !(radius_m >= 0.0)) {
    throw Error("submap centre grid: query at a non-finite centre or with radius " +
                std::to_string(radius_m) + " m");
  }
  const Eigen::Vector3d low = centre_W.array() - radius_m, high = centre_W.array() + radius_m;
  std::vector<int> near;
  for (std::int64_t x = CellCoordinate(low.x(), cell_m_); x <= CellCoordinate(high.x(), cell_m_);
       ++x) {
    for (std::int64_t y = CellCoordinate(low.y(), cell_m_); y <= CellCoordinate(high.y(), cell_m_);
         ++y) {
      for (std::int64_t z = CellCoordinate(low.z(), cell_m_);
           z <= CellCoordinate(high.z(), cell_m_); ++z) {
        const auto cell = cells_.find(KeyOfCell(x, y, z));
        if (cell != cells_.end()) near.insert(near.end(), cell->second.begin(), cell->second.end());
      }
    }
  }
  std::sort(near.begin(), near.end());
  return near;
}

}  // namespace uwscan::mapping
