#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

struct ClusteringOptions {
  double tolerance_m = 0.02;  // metres, points closer than this join one cluster; > 0
  std::size_t min_size = 1;   // clusters with fewer points are dropped, >= 1
  std::size_t max_size =
      std::numeric_limits<std::size_t>::max();  // larger ones dropped, >= min_size

  // Throws uwscan::Error naming the field when it is out of range.
  void Check() const;
};

// Euclidean cluster extraction (Rusu 2009, as PCL's EuclideanClusterExtraction): the connected
// components of the graph linking points closer than tolerance_m. Each cluster is a list of
// increasing indices into the cloud; clusters come largest first, equal sizes by their smallest
// index. Empty cloud: no cluster. Throws uwscan::Error on a non-finite point, or when the cloud
// spans more than 2^21 tolerances along an axis (the search grid's limit).
std::vector<std::vector<std::size_t>> EuclideanClusters(const PointCloud& cloud,
                                                        const ClusteringOptions& options);

}  // namespace uwscan::perception
