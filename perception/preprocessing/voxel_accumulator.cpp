#include "perception/preprocessing/voxel_accumulator.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {

VoxelAccumulator::VoxelAccumulator(double leaf_m, const Eigen::Vector3d& origin)
    : leaf_m_(leaf_m), origin_(origin) {
  if (!(leaf_m > 0.0) || !std::isfinite(leaf_m))
    throw Error("VoxelAccumulator: leaf_m must be finite and > 0, got " + std::to_string(leaf_m));
  if (!origin.allFinite()) throw Error("VoxelAccumulator: the origin must be finite");
}

void VoxelAccumulator::Add(const PointCloud& cloud, const Eigen::Isometry3d& T) {
  constexpr double kMaxKey = 4.611686018427387904e18;  // 2^62, as VoxelDownsample
  // Relative to the merged origin in double, then stored in float, as a merged cloud would be.
  const Eigen::Isometry3d T_relative = Eigen::Translation3d(-origin_) * T;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = (T_relative * cloud.Point(i)).cast<float>();
    const Eigen::Vector3d absolute = origin_ + p.cast<double>();
    if (!absolute.allFinite())
      throw Error("VoxelAccumulator: point " + std::to_string(i) + " is not finite");
    VoxelKey key;
    for (int a = 0; a < 3; ++a) {
      const double k = std::floor(absolute[a] / leaf_m_);
      if (!(std::abs(k) < kMaxKey)) {
        throw Error("VoxelAccumulator: leaf_m " + std::to_string(leaf_m_) +
                    " m is too small for coordinate " + std::to_string(absolute[a]) +
                    " m (voxel key overflows 64 bits)");
      }
      key[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(k);
    }
    const std::uint32_t id = voxels_.Insert(key);
    // resize, not emplace_back: a failed allocation leaves no id without its sum.
    if (id >= sums_.size()) sums_.resize(id + std::size_t{1});
    Sum& voxel = sums_[id];
    voxel.sum += p.cast<double>();
    ++voxel.count;
  }
}

PointCloud VoxelAccumulator::Cloud() const {
  PointCloud out;
  out.origin = origin_;
  out.points.reserve(sums_.size());
  for (const std::uint32_t id : voxels_.IdsByKey())
    out.points.push_back((sums_[id].sum / static_cast<double>(sums_[id].count)).cast<float>());
  return out;
}

}  // namespace uwscan::perception
