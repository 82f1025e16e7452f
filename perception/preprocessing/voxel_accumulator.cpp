#include "perception/preprocessing/voxel_accumulator.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {

std::size_t VoxelAccumulator::KeyHash::operator()(const Key& k) const {
  // Large odd multipliers spread neighbouring voxels over the table.
  const auto x = static_cast<std::uint64_t>(k[0]) * 0x9E3779B97F4A7C15ull;
  const auto y = static_cast<std::uint64_t>(k[1]) * 0xC2B2AE3D27D4EB4Full;
  const auto z = static_cast<std::uint64_t>(k[2]) * 0x165667B19E3779F9ull;
  return static_cast<std::size_t>(x ^ (y >> 1) ^ (z << 1));
}

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
    Key key;
    for (int a = 0; a < 3; ++a) {
      const double k = std::floor(absolute[a] / leaf_m_);
      if (!(std::abs(k) < kMaxKey)) {
        throw Error("VoxelAccumulator: leaf_m " + std::to_string(leaf_m_) +
                    " m is too small for coordinate " + std::to_string(absolute[a]) +
                    " m (voxel key overflows 64 bits)");
      }
      key[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(k);
    }
    Sum& voxel = voxels_[key];
    voxel.sum += p.cast<double>();
    ++voxel.count;
  }
}

PointCloud VoxelAccumulator::Cloud() const {
  std::vector<const std::pair<const Key, Sum>*> sorted;
  sorted.reserve(voxels_.size());
  for (const auto& entry : voxels_) sorted.push_back(&entry);
  std::sort(sorted.begin(), sorted.end(),
            [](const auto* a, const auto* b) { return a->first < b->first; });
  PointCloud out;
  out.origin = origin_;
  out.points.reserve(sorted.size());
  for (const auto* entry : sorted)
    out.points.push_back(
        (entry->second.sum / static_cast<double>(entry->second.count)).cast<float>());
  return out;
}

}  // namespace uwscan::perception
