#include "perception/preprocessing/outlier_filter.hpp"

#include <omp.h>

#include <cmath>
#include <cstdint>

#include "perception/cloud/cloud_neighbors.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {

void OutlierFilterOptions::Check() const {
  const OptionChecks check("OutlierFilterOptions");
  check.AtLeast("k", k, 1);
  check.Finite("std_ratio", std_ratio);
  check.AtLeast("threads", threads, 0);
}

OutlierFilterResult RemoveStatisticalOutliers(const PointCloud& cloud,
                                              const OutlierFilterOptions& options) {
  options.Check();
  RequireValidCloud(cloud, "RemoveStatisticalOutliers: input cloud", 0);
  OutlierFilterResult result;
  const std::size_t n = cloud.size();
  if (n < 2) {
    result.cloud = cloud;
    for (std::size_t i = 0; i < n; ++i) result.kept_indices.push_back(i);
    return result;
  }

  const KnnIndex index(cloud.points);
  const int k_search =
      static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(options.k), n - 1)) + 1;
  std::vector<double> mean_distance(n);
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel num_threads(threads)
  {
    std::vector<std::uint32_t> nn;
    std::vector<float> d2;
#pragma omp for schedule(static)
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
      index.Query(cloud.points[static_cast<std::size_t>(i)], k_search, nn, d2);
      // The nearest result is the point itself (or a duplicate of it): distance 0, skipped.
      double sum = 0.0;
      for (std::size_t j = 1; j < d2.size(); ++j) sum += std::sqrt(static_cast<double>(d2[j]));
      mean_distance[static_cast<std::size_t>(i)] = sum / static_cast<double>(d2.size() - 1);
    }
  }

  // Two passes (mean, then squared deviations): no cancellation.
  const double count = static_cast<double>(n);
  double sum = 0.0;
  for (double d : mean_distance) sum += d;
  result.mean_distance_m = sum / count;
  double sum_sq = 0.0;
  for (double d : mean_distance)
    sum_sq += (d - result.mean_distance_m) * (d - result.mean_distance_m);
  result.std_distance_m = std::sqrt(sum_sq / (count - 1.0));
  result.threshold_m = result.mean_distance_m + options.std_ratio * result.std_distance_m;

  for (std::size_t i = 0; i < n; ++i) {
    if (mean_distance[i] <= result.threshold_m) result.kept_indices.push_back(i);
  }
  result.num_removed = n - result.kept_indices.size();
  result.cloud = Subset(cloud, result.kept_indices);
  return result;
}

}  // namespace uwscan::perception
