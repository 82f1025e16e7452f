#include "perception/preprocessing/clustering.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "perception/cloud/cloud_neighbors.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {

void ClusteringOptions::Check() const {
  const OptionChecks check("ClusteringOptions");
  check.Positive("tolerance_m", tolerance_m, "m");
  check.AtLeast("min_size", min_size, 1);
  check.Require(max_size >= min_size, "max_size", ">= min_size (" + std::to_string(min_size) + ")",
                max_size);
}

std::vector<std::vector<std::size_t>> EuclideanClusters(const PointCloud& cloud,
                                                        const ClusteringOptions& options) {
  options.Check();
  RequireValidCloud(cloud, "EuclideanClusters: input cloud", 0);
  std::vector<std::vector<std::size_t>> clusters;
  if (cloud.empty()) return clusters;

  const RadiusGrid grid(cloud.points, options.tolerance_m);
  std::vector<std::uint8_t> visited(cloud.size(), 0);
  std::vector<std::uint32_t> neighbours;
  std::vector<float> d2;
  std::vector<std::size_t> cluster;
  for (std::size_t seed = 0; seed < cloud.size(); ++seed) {
    if (visited[seed]) continue;
    // Breadth-first flood fill; `cluster` doubles as the queue.
    cluster.assign(1, seed);
    visited[seed] = 1;
    for (std::size_t head = 0; head < cluster.size(); ++head) {
      grid.Query(cloud.points[cluster[head]], neighbours, d2);
      for (std::uint32_t j : neighbours) {
        if (visited[j]) continue;
        visited[j] = 1;
        cluster.push_back(j);
      }
    }
    if (cluster.size() < options.min_size || cluster.size() > options.max_size) continue;
    std::sort(cluster.begin(), cluster.end());
    clusters.push_back(cluster);
  }
  // Seeds are visited in increasing order, so clusters are already ordered by smallest index.
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return clusters;
}

}  // namespace uwscan::perception
