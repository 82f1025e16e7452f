#include "perception/preprocessing/voxel_filter.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

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

  struct Entry {
    std::array<std::int64_t, 3> key;
    std::size_t index;
  };
  constexpr double kMaxKey = 4.611686018427387904e18;  // 2^62
  std::vector<Entry> entries(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.Point(i);
    for (int a = 0; a < 3; ++a) {
      const double k = std::floor(p[a] / options.leaf_m);
      if (!(std::abs(k) < kMaxKey)) {
        throw Error("VoxelDownsample: leaf_m " + std::to_string(options.leaf_m) +
                    " m is too small for coordinate " + std::to_string(p[a]) + " m of point " +
                    std::to_string(i) + " (voxel key overflows 64 bits)");
      }
      entries[i].key[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(k);
    }
    entries[i].index = i;
  }
  // Element by element: std::array's own comparisons call memcmp, a third of this function's time.
  const auto same_voxel = [](const Entry& a, const Entry& b) {
    return a.key[0] == b.key[0] && a.key[1] == b.key[1] && a.key[2] == b.key[2];
  };
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    if (a.key[0] != b.key[0]) return a.key[0] < b.key[0];
    if (a.key[1] != b.key[1]) return a.key[1] < b.key[1];
    if (a.key[2] != b.key[2]) return a.key[2] < b.key[2];
    return a.index < b.index;
  });

  for (std::size_t begin = 0; begin < entries.size();) {
    std::size_t end = begin;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (end < entries.size() && same_voxel(entries[end], entries[begin])) {
      sum += cloud.points[entries[end].index].cast<double>();
      ++end;
    }
    out.points.push_back((sum / static_cast<double>(end - begin)).cast<float>());
    begin = end;
  }
  return out;
}

}  // namespace uwscan::perception
