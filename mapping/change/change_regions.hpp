#pragma once

#include <Eigen/Core>
#include <vector>

#include "mapping/change/surface_deviation.hpp"

namespace uwscan::mapping {

// A connected patch of surface that changed: significant core points of one sign (gained or
// lost), each within `link_m` of another.
struct ChangeRegion {
  int id = 0;  // from 0, by decreasing area
  std::vector<std::size_t> core_indices;
  Eigen::Vector3d centroid_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d extent_m = Eigen::Vector3d::Zero();  // along its principal axes, largest first
  double area_m2 = 0.0;                                // core points x core spacing squared
  double mean_deviation_m = 0.0;
  double extreme_deviation_m = 0.0;  // the deviation farthest from zero
  double volume_m3 = 0.0;            // sum of deviation x cell area: > 0 gained, < 0 lost
  // How far beyond its level of detection the region's mean lies: mean |deviation| over mean
  // level of detection (> 1 for every significant region).
  double significance = 0.0;
};

struct RegionOptions {
  double link_m = 0.0;  // 0: 1.8 core spacings (a cell's diagonal neighbours), metres, >= 0
  // Smaller groups are not reported as regions (>= 1): at 95 % confidence one core point in twenty
  // on unchanged surface is flagged by chance, and such specks are noise, not findings. 8 points
  // 1 cm apart is a patch about 3 cm across.
  int min_core_points = 8;
  void Check() const;
};

// The significant core points grouped into regions, largest first. `region_of` receives each
// core point's region id, -1 outside any.
std::vector<ChangeRegion> FindChangeRegions(const std::vector<CoreDeviation>& deviations,
                                            double core_spacing_m, const RegionOptions& options,
                                            std::vector<int>& region_of);

}  // namespace uwscan::mapping
