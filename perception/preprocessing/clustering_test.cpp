#include "perception/preprocessing/clustering.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

void AddSphere(const Eigen::Vector3d& centre, double radius, int n,
               std::vector<Eigen::Vector3d>* out) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n;
    const double r = std::sqrt(1.0 - z * z);
    out->push_back(centre +
                   radius * Eigen::Vector3d(r * std::cos(golden * i), r * std::sin(golden * i), z));
  }
}

TEST(EuclideanClusters, SeparatesTwoSpheres) {
  std::vector<Eigen::Vector3d> points;
  AddSphere({0, 0, 0}, 0.2, 800, &points);        // spacing about 2.5 cm
  AddSphere({0.6, 0.1, 0}, 0.25, 1500, &points);  // a 16 cm gap between the surfaces
  const PointCloud cloud = MakeCloud(points);
  const auto clusters = EuclideanClusters(cloud, {.tolerance_m = 0.05});
  ASSERT_EQ(clusters.size(), 2u);
  // Largest first: the second sphere.
  ASSERT_EQ(clusters[0].size(), 1500u);
  ASSERT_EQ(clusters[1].size(), 800u);
  EXPECT_EQ(clusters[0].front(), 800u);
  EXPECT_EQ(clusters[0].back(), 2299u);
  EXPECT_EQ(clusters[1].front(), 0u);
  EXPECT_TRUE(std::is_sorted(clusters[0].begin(), clusters[0].end()));
  // A tolerance wider than the gap joins them.
  EXPECT_EQ(EuclideanClusters(cloud, {.tolerance_m = 0.25}).size(), 1u);
}

TEST(EuclideanClusters, SizeLimitsAndOrderOfEqualSizes) {
  std::vector<Eigen::Vector3d> points;
  for (int c = 0; c < 3; ++c) {
    for (int i = 0; i < 10; ++i) points.emplace_back(c * 1.0, 0.01 * i, 0.0);
  }
  points.emplace_back(10.0, 0.0, 0.0);  // a lone point
  const PointCloud cloud = MakeCloud(points);
  const auto all = EuclideanClusters(cloud, {.tolerance_m = 0.02});
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[0].front(), 0u);  // equal sizes: by smallest index
  EXPECT_EQ(all[1].front(), 10u);
  EXPECT_EQ(all[2].front(), 20u);
  EXPECT_EQ(all[3], std::vector<std::size_t>{30u});
  EXPECT_EQ(EuclideanClusters(cloud, {.tolerance_m = 0.02, .min_size = 2}).size(), 3u);
  EXPECT_EQ(EuclideanClusters(cloud, {.tolerance_m = 0.02, .min_size = 1, .max_size = 5}).size(),
            1u);
}

TEST(EuclideanClusters, EmptyDuplicatesAndBadInput) {
  EXPECT_TRUE(EuclideanClusters(PointCloud{}, {}).empty());
  const std::vector<Eigen::Vector3d> same(50, Eigen::Vector3d(3, 3, 3));
  const auto one = EuclideanClusters(MakeCloud(same), {});
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].size(), 50u);
  PointCloud cloud = MakeCloud(same);
  EXPECT_THROW(EuclideanClusters(cloud, {.tolerance_m = 0.0}), Error);
  EXPECT_THROW(EuclideanClusters(cloud, {.min_size = 0}), Error);
  EXPECT_THROW(EuclideanClusters(cloud, {.min_size = 5, .max_size = 4}), Error);
  cloud.points[1].z() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(EuclideanClusters(cloud, {}), Error);
}

}  // namespace
}  // namespace uwscan::perception
