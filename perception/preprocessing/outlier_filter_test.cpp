#include "perception/preprocessing/outlier_filter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// A noisy 1 m x 1 m plane sampled every 2 cm with `outliers` points planted 0.2-0.5 m above it.
PointCloud PlaneWithOutliers(int outliers, std::vector<std::size_t>* outlier_indices) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.001);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 50; ++i) {
    for (int j = 0; j < 50; ++j) points.emplace_back(0.02 * i, 0.02 * j, noise(rng));
  }
  for (int o = 0; o < outliers; ++o) {
    outlier_indices->push_back(points.size());
    points.push_back({u(rng), u(rng), 0.2 + 0.3 * u(rng)});
  }
  return MakeCloud(points);
}

TEST(RemoveStatisticalOutliers, RemovesPlantedOutliers) {
  std::vector<std::size_t> planted;
  const PointCloud cloud = PlaneWithOutliers(30, &planted);
  const OutlierFilterResult result = RemoveStatisticalOutliers(cloud, {.k = 10, .std_ratio = 1.0});
  for (std::size_t i : planted) {
    EXPECT_FALSE(std::binary_search(result.kept_indices.begin(), result.kept_indices.end(), i))
        << "outlier " << i << " kept";
  }
  // Nearly every plane point stays.
  EXPECT_GE(result.kept_indices.size(), 2500u * 95 / 100);
  EXPECT_EQ(result.num_removed, cloud.size() - result.kept_indices.size());
  EXPECT_EQ(result.cloud.size(), result.kept_indices.size());
  EXPECT_EQ(result.cloud.origin, cloud.origin);
  EXPECT_TRUE(std::is_sorted(result.kept_indices.begin(), result.kept_indices.end()));
  EXPECT_NEAR(result.threshold_m, result.mean_distance_m + result.std_distance_m, 1e-12);
}

TEST(RemoveStatisticalOutliers, SameResultWithOneAndTwoThreads) {
  std::vector<std::size_t> planted;
  const PointCloud cloud = PlaneWithOutliers(30, &planted);
  const OutlierFilterResult a = RemoveStatisticalOutliers(cloud, {.k = 8, .threads = 1});
  const OutlierFilterResult b = RemoveStatisticalOutliers(cloud, {.k = 8, .threads = 2});
  EXPECT_EQ(a.kept_indices, b.kept_indices);
  EXPECT_EQ(a.threshold_m, b.threshold_m);
}

TEST(RemoveStatisticalOutliers, TinyAndDegenerateClouds) {
  const OutlierFilterResult empty = RemoveStatisticalOutliers(PointCloud{}, {});
  EXPECT_TRUE(empty.kept_indices.empty());
  EXPECT_TRUE(empty.cloud.empty());
  const std::vector<Eigen::Vector3d> one = {{5.0, 5.0, 5.0}};
  EXPECT_EQ(RemoveStatisticalOutliers(MakeCloud(one), {}).kept_indices.size(), 1u);
  // Fewer points than k: all the others form the neighbourhood.
  const std::vector<Eigen::Vector3d> three = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  const OutlierFilterResult r = RemoveStatisticalOutliers(MakeCloud(three), {.k = 20});
  EXPECT_EQ(r.kept_indices.size() + r.num_removed, 3u);
  // All points identical: every distance 0, nothing removed.
  const std::vector<Eigen::Vector3d> same(10, Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(RemoveStatisticalOutliers(MakeCloud(same), {.k = 3}).num_removed, 0u);
}

TEST(RemoveStatisticalOutliers, RejectsBadInput) {
  std::vector<std::size_t> planted;
  PointCloud cloud = PlaneWithOutliers(0, &planted);
  EXPECT_THROW(RemoveStatisticalOutliers(cloud, {.k = 0}), Error);
  EXPECT_THROW(RemoveStatisticalOutliers(cloud, {.std_ratio = std::nan("")}), Error);
  EXPECT_THROW(RemoveStatisticalOutliers(cloud, {.threads = -1}), Error);
  cloud.points[10].z() = std::numeric_limits<float>::infinity();
  EXPECT_THROW(RemoveStatisticalOutliers(cloud, {}), Error);
}

}  // namespace
}  // namespace uwscan::perception
