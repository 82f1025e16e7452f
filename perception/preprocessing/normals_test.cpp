#include "perception/preprocessing/normals.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// Fibonacci sphere: n nearly uniform points.
std::vector<Eigen::Vector3d> Sphere(const Eigen::Vector3d& centre, double radius, int n) {
  std::vector<Eigen::Vector3d> points;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n;
    const double r = std::sqrt(1.0 - z * z);
    points.push_back(
        centre + radius * Eigen::Vector3d(r * std::cos(golden * i), r * std::sin(golden * i), z));
  }
  return points;
}

// Two perpendicular 0.4 m x 0.4 m faces meeting along the y axis (z = 0 for x >= 0, x = 0 for
// z >= 0), sampled every 1 cm.
std::vector<Eigen::Vector3d> Dihedral() {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) {
      points.emplace_back(0.01 * i, 0.01 * j, 0.0);
      if (i > 0) points.emplace_back(0.0, 0.01 * j, 0.01 * i);
    }
  }
  return points;
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(EstimateNormals, SpherePointsRadiallyTowardTheViewpoint) {
  const Eigen::Vector3d centre(1.0, 2.0, 3.0);
  const PointCloud cloud = MakeCloud(Sphere(centre, 0.5, 5000));
  // Viewpoint at the centre: every normal points inward.
  NormalsResult inward = EstimateNormals(cloud, {.k = 20, .viewpoint = centre});
  ASSERT_EQ(inward.normals.size(), cloud.size());
  EXPECT_EQ(inward.num_invalid, 0u);
  double worst = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    worst =
        std::max(worst, AngleBetween(inward.normals[i].cast<double>(), centre - cloud.Point(i)));
  }
  EXPECT_LT(worst, 1.0 * kDegree);
  // Viewpoint outside, above the sphere: normals face it, so those on the near side point out.
  const Eigen::Vector3d viewpoint = centre + Eigen::Vector3d(0.0, 0.0, 5.0);
  NormalsResult outside = EstimateNormals(cloud, {.k = 20, .viewpoint = viewpoint});
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d n = outside.normals[i].cast<double>();
    EXPECT_GE(n.dot(viewpoint - cloud.Point(i)), 0.0) << i;
    EXPECT_NEAR(n.norm(), 1.0, 1e-6);
    if (cloud.Point(i).z() > centre.z() + 0.1) {
      EXPECT_LT(AngleBetween(n, cloud.Point(i) - centre), 1.0 * kDegree) << i;
    }
  }
  // Curvature of a sphere sampled this densely is small but not zero.
  for (float c : inward.curvatures) {
    EXPECT_GT(c, 0.0f);
    EXPECT_LT(c, 0.01f);
  }
}

TEST(EstimateNormals, RadiusNeighbourhoodAndHugeCoordinates) {
  const Eigen::Vector3d centre(1e6, -2e6, 5e5);
  const PointCloud cloud = MakeCloud(Sphere(centre, 0.5, 5000));
  const NormalsResult r = EstimateNormals(cloud, {.radius_m = 0.04, .viewpoint = centre});
  EXPECT_EQ(r.num_invalid, 0u);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_LT(AngleBetween(r.normals[i].cast<double>(), centre - cloud.Point(i)), 1.0 * kDegree);
  }
}

TEST(EstimateNormals, CurvatureNearZeroOnPlanesAndHigherOnTheEdge) {
  const PointCloud cloud = MakeCloud(Dihedral());
  const NormalsResult r = EstimateNormals(cloud, {.k = 15, .viewpoint = {1.0, 0.2, 1.0}});
  EXPECT_EQ(r.num_invalid, 0u);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.Point(i);
    const double to_edge = std::max(p.x(), p.z());  // distance from the edge line (x = z = 0)
    if (to_edge > 0.05) {
      EXPECT_LT(r.curvatures[i], 1e-5f) << p.transpose();
      const Eigen::Vector3d expected =
          p.z() < 1e-9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
      EXPECT_GT(r.normals[i].cast<double>().dot(expected), 0.9999);
    }
    if (to_edge < 1e-9 && p.y() > 0.05 && p.y() < 0.35) {
      EXPECT_GT(r.curvatures[i], 0.05f) << p.transpose();
    }
  }
}

TEST(EstimateNormals, SameResultWithOneAndTwoThreads) {
  const PointCloud cloud = MakeCloud(Sphere(Eigen::Vector3d::Zero(), 0.3, 3000));
  const NormalsResult a = EstimateNormals(cloud, {.k = 12, .threads = 1});
  const NormalsResult b = EstimateNormals(cloud, {.k = 12, .threads = 2});
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.curvatures, b.curvatures);
}

TEST(EstimateNormals, DegenerateCloudsGiveInvalidNormalsNotGarbage) {
  EXPECT_TRUE(EstimateNormals(PointCloud{}, {}).normals.empty());

  const std::vector<Eigen::Vector3d> one = {{1, 2, 3}};
  const NormalsResult single = EstimateNormals(MakeCloud(one), {});
  ASSERT_EQ(single.normals.size(), 1u);
  EXPECT_EQ(single.num_invalid, 1u);
  EXPECT_TRUE(std::isnan(single.normals[0].x()));
  EXPECT_TRUE(std::isnan(single.curvatures[0]));

  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(10.0 + 0.01 * i, 0.02 * i, -0.03 * i);
  const NormalsResult collinear = EstimateNormals(MakeCloud(line), {.k = 10});
  EXPECT_EQ(collinear.num_invalid, line.size());

  const std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(EstimateNormals(MakeCloud(same), {.k = 3}).num_invalid, 5u);
}

TEST(EstimateNormals, RejectsBadInput) {
  PointCloud cloud = MakeCloud(Dihedral());
  EXPECT_THROW(EstimateNormals(cloud, {.k = 2}), Error);
  EXPECT_THROW(EstimateNormals(cloud, {.radius_m = -0.1}), Error);
  EXPECT_THROW(EstimateNormals(cloud, {.viewpoint = Eigen::Vector3d::Constant(std::nan(""))}),
               Error);
  cloud.points[0].y() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(EstimateNormals(cloud, {}), Error);
}

TEST(AttachNormals, KeepsOnlyValidNormals) {
  std::vector<Eigen::Vector3d> points = Dihedral();
  // Two isolated points: no neighbour within the radius, no normal.
  points.emplace_back(5.0, 5.0, 5.0);
  points.emplace_back(9.0, 9.0, 9.0);
  const PointCloud cloud = MakeCloud(points);
  const NormalsResult normals = EstimateNormals(cloud, {.radius_m = 0.025});
  EXPECT_EQ(normals.num_invalid, 2u);
  const CloudWithNormals attached = AttachNormals(cloud, normals);
  ASSERT_EQ(attached.cloud.size(), cloud.size() - 2);
  EXPECT_TRUE(attached.cloud.has_normals());
  EXPECT_EQ(attached.curvatures.size(), attached.cloud.size());
  EXPECT_EQ(attached.source_indices.back(), cloud.size() - 3);
  EXPECT_NO_THROW(RequireValidCloud(attached.cloud, "attached"));
  EXPECT_THROW(AttachNormals(cloud, NormalsResult{}), Error);
}

}  // namespace
}  // namespace uwscan::perception
