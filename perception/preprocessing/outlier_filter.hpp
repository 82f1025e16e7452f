#pragma once

#include <cstddef>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

struct OutlierFilterOptions {
  int k = 20;              // neighbours per point (the point itself not counted), >= 1
  double std_ratio = 1.0;  // threshold in standard deviations above the mean, finite
  int threads = 0;         // OpenMP threads, 0 = OpenMP's default; the result does not depend on it

  // Throws uwscan::Error naming the field when it is out of range.
  void Check() const;
};

struct OutlierFilterResult {
  PointCloud cloud;                       // the kept points (normals kept when present)
  std::vector<std::size_t> kept_indices;  // increasing indices into the input cloud
  std::size_t num_removed = 0;
  double mean_distance_m = 0.0;  // mean over all points of their mean distance to k neighbours
  double std_distance_m = 0.0;   // sample standard deviation of those per-point means
  double threshold_m = 0.0;      // mean_distance_m + std_ratio * std_distance_m
};

// Statistical outlier removal (as PCL's StatisticalOutlierRemoval): for each point, the mean
// Euclidean distance d_i to its k nearest neighbours; points with d_i > mean(d) + std_ratio *
// std(d) are removed. Clouds with fewer than k + 1 points use all the other points as the
// neighbourhood; a cloud of 0 or 1 point is returned whole. Throws uwscan::Error on a
// non-finite point.
OutlierFilterResult RemoveStatisticalOutliers(const PointCloud& cloud,
                                              const OutlierFilterOptions& options);

}  // namespace uwscan::perception
