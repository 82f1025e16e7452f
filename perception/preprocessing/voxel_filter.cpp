#include "perception/preprocessing/voxel_filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "perception/preprocessing/voxel_index.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {

void VoxelFilterOptions::Check() const {
  OptionChecks("VoxelFilterOptions").Positive("leaf_m", leaf_m, "m");
}

PointCloud VoxelDownsample(const PointCloud& cloud, const VoxelFilterOptions& options) {
  options.Check();
  RequireValidCloud(cloud, "VoxelDownsample: input cloud", 0);
  PointCloud out;
  out.origin = cloud.origin;
  if (cloud.empty()) return out;

  constexpr double kMaxKey = 4.611686018427387904e18;  // 2^62
  // Each voxel's sum and count, its points added in index order.
  VoxelIndex voxels;
  std::vector<Eigen::Vector3d> sums;
  std::vector<std::int64_t> counts;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.Point(i);
    VoxelKey key;
    for (int a = 0; a < 3; ++a) {
      const double k = std::floor(p[a] / options.leaf_m);
      if (!(std::abs(k) < kMaxKey)) {
        throw Error("VoxelDownsample: leaf_m " + std::to_string(options.leaf_m) +
                    " m is too small for coordinate " + std::to_string(p[a]) + " m of point " +
                    std::to_string(i) + " (voxel key overflows 64 bits)");
      }
      key[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(k);
    }
    const std::uint32_t id = voxels.Insert(key);
    if (id == sums.size()) {
      sums.push_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    sums[id] += cloud.points[i].cast<double>();
    ++counts[id];
  }
  out.points.reserve(sums.size());
  for (const std::uint32_t id : voxels.IdsByKey())
    out.points.push_back((sums[id] / static_cast<double>(counts[id])).cast<float>());
  return out;
}

}  // namespace uwscan::perception
