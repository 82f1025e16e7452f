#include "perception/features/keypoints.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "perception/preprocessing/normals.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

TEST(CurvatureKeypoints, SelectsPointsAboveTheThreshold) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> curvatures = {0.0f, 0.02f, 0.01f, nan, 0.3f, 0.005f};
  EXPECT_EQ(CurvatureKeypoints(curvatures, {.min_curvature = 0.01}),
            (std::vector<std::size_t>{1, 4}));
  EXPECT_EQ(CurvatureKeypoints(curvatures, {.min_curvature = 0.0}),
            (std::vector<std::size_t>{1, 2, 4, 5}));
  EXPECT_TRUE(CurvatureKeypoints({}, {}).empty());
  EXPECT_THROW(CurvatureKeypoints(curvatures, {.min_curvature = -0.1}), Error);
  EXPECT_THROW(CurvatureKeypoints(curvatures, {.min_curvature = 0.5}), Error);
  EXPECT_THROW(CurvatureKeypoints(curvatures, {.min_curvature = std::nan("")}), Error);
}

TEST(CurvatureKeypoints, FindsTheEdgesOfACube) {
  // A 0.2 m cube's surface sampled every 1 cm: keypoints lie on or next to its edges.
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= 20; ++i) {
    for (int j = 0; j <= 20; ++j) {
      const double a = 0.01 * i, b = 0.01 * j;
      for (const Eigen::Vector3d& p :
           {Eigen::Vector3d(a, b, 0), Eigen::Vector3d(a, b, 0.2), Eigen::Vector3d(a, 0, b),
            Eigen::Vector3d(a, 0.2, b), Eigen::Vector3d(0, a, b), Eigen::Vector3d(0.2, a, b)}) {
        points.push_back(p);
      }
    }
  }
  const PointCloud cloud = MakeCloud(points);
  const NormalsResult normals = EstimateNormals(cloud, {.k = 12});
  const std::vector<std::size_t> keypoints =
      CurvatureKeypoints(normals.curvatures, {.min_curvature = 0.02});
  ASSERT_FALSE(keypoints.empty());
  for (std::size_t k : keypoints) {
    const Eigen::Vector3d p = cloud.Point(k);
    // Distance to the nearest face boundary: small for edge points.
    int near_faces = 0;
    for (int a = 0; a < 3; ++a) near_faces += (p[a] < 0.025 || p[a] > 0.175) ? 1 : 0;
    EXPECT_GE(near_faces, 2) << p.transpose();
  }
}

}  // namespace
}  // namespace uwscan::perception
