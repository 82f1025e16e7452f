#include "perception/preprocessing/plane_removal.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// A 2 m x 2 m floor (z = 0) and a 2 m x 1 m wall (y = 1), sampled every 2 cm, with a 0.3 m box
// on the floor (5 faces, sampled every 2 cm), 1 mm noise, far from the frame origin.
struct BoxScene {
  PointCloud cloud;
  std::vector<std::size_t> box;  // indices of the box points
  std::size_t floor_points = 0, wall_points = 0;
};

BoxScene MakeBoxScene(const Eigen::Vector3d& offset) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.001);
  auto jitter = [&] { return Eigen::Vector3d{noise(rng), noise(rng), noise(rng)}; };
  BoxScene scene;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      const Eigen::Vector3d p(-1.0 + 0.02 * i, -1.0 + 0.02 * j, 0.0);
      // The box's footprint is not floor.
      if (std::abs(p.x()) < 0.15 && std::abs(p.y()) < 0.15) continue;
      points.push_back(offset + p + jitter());
      ++scene.floor_points;
    }
  }
  for (int i = 0; i < 100; ++i) {
    for (int k = 1; k <= 50; ++k) {
      points.push_back(offset + Eigen::Vector3d(-1.0 + 0.02 * i, 1.0, 0.02 * k) + jitter());
      ++scene.wall_points;
    }
  }
  for (int i = 0; i <= 15; ++i) {
    for (int j = 0; j <= 15; ++j) {
      const double a = -0.15 + 0.02 * i, b = -0.15 + 0.02 * j, c = 0.02 * j;
      const Eigen::Vector3d faces[5] = {
          {a, b, 0.3}, {-0.15, a, c}, {0.15, a, c}, {a, -0.15, c}, {a, 0.15, c}};
      for (const Eigen::Vector3d& f : faces) {
        scene.box.push_back(points.size());
        points.push_back(offset + f + jitter());
      }
    }
  }
  scene.cloud = MakeCloud(points);
  return scene;
}

PlaneRemovalOptions SceneOptions() {
  PlaneRemovalOptions o;
  o.distance_threshold_m = 0.01;
  o.min_fraction = 0.1;
  o.max_planes = 5;
  o.seed = 42;
  return o;
}

TEST(RemovePlanes, RemovesFloorAndWallKeepsTheBox) {
  const BoxScene scene = MakeBoxScene(Eigen::Vector3d(1e5, -2e5, 30.0));
  const PlaneRemovalResult r = RemovePlanes(scene.cloud, SceneOptions());
  ASSERT_EQ(r.planes.size(), 2u);
  // Floor first (it is larger), then wall; normals up to sign.
  EXPECT_GT(std::abs(r.planes[0].normal.z()), 0.999);
  EXPECT_NEAR(
      std::abs(r.planes[0].normal.dot(Eigen::Vector3d(1e5, -2e5, 30.0)) + r.planes[0].offset_m),
      0.0, 0.005);
  EXPECT_GT(std::abs(r.planes[1].normal.y()), 0.999);
  EXPECT_GE(r.planes[0].inliers.size(), scene.floor_points * 98 / 100);
  EXPECT_GE(r.planes[1].inliers.size(), scene.wall_points * 98 / 100);
  // The box stays, apart from its bottom rows within the floor's inlier band.
  std::size_t box_kept = 0;
  for (std::size_t i : scene.box) {
    box_kept += std::binary_search(r.remaining_indices.begin(), r.remaining_indices.end(), i);
  }
  EXPECT_GE(box_kept, scene.box.size() * 90 / 100);
  EXPECT_EQ(r.remaining.size(), r.remaining_indices.size());
  EXPECT_EQ(r.remaining.origin, scene.cloud.origin);
  EXPECT_EQ(r.remaining.size() + r.planes[0].inliers.size() + r.planes[1].inliers.size(),
            scene.cloud.size());
}

TEST(RemovePlanes, SameSeedSameResultForAnyThreadCount) {
  const BoxScene scene = MakeBoxScene(Eigen::Vector3d::Zero());
  PlaneRemovalOptions o = SceneOptions();
  o.threads = 1;
  const PlaneRemovalResult a = RemovePlanes(scene.cloud, o);
  const PlaneRemovalResult again = RemovePlanes(scene.cloud, o);
  o.threads = 2;
  const PlaneRemovalResult b = RemovePlanes(scene.cloud, o);
  for (const PlaneRemovalResult* other : {&again, &b}) {
    ASSERT_EQ(other->planes.size(), a.planes.size());
    EXPECT_EQ(other->remaining_indices, a.remaining_indices);
    for (std::size_t p = 0; p < a.planes.size(); ++p) {
      EXPECT_EQ(other->planes[p].normal, a.planes[p].normal);
      EXPECT_EQ(other->planes[p].offset_m, a.planes[p].offset_m);
      EXPECT_EQ(other->planes[p].inliers, a.planes[p].inliers);
    }
  }
  // Another seed finds the same two planes.
  o.seed = 7;
  const PlaneRemovalResult c = RemovePlanes(scene.cloud, o);
  ASSERT_EQ(c.planes.size(), 2u);
  EXPECT_GT(std::abs(c.planes[0].normal.dot(a.planes[0].normal)), 0.999);
}

TEST(RemovePlanes, MinFractionAndMaxPlanesStopTheSearch) {
  const BoxScene scene = MakeBoxScene(Eigen::Vector3d::Zero());
  PlaneRemovalOptions o = SceneOptions();
  o.max_planes = 1;
  EXPECT_EQ(RemovePlanes(scene.cloud, o).planes.size(), 1u);
  o.max_planes = 0;
  EXPECT_EQ(RemovePlanes(scene.cloud, o).remaining.size(), scene.cloud.size());
  o.max_planes = 5;
  o.min_fraction = 0.5;  // the floor holds about 0.6 of the points, the wall 0.3
  EXPECT_EQ(RemovePlanes(scene.cloud, o).planes.size(), 1u);
  o.min_fraction = 0.9;
  EXPECT_TRUE(RemovePlanes(scene.cloud, o).planes.empty());
}

TEST(RemovePlanes, DegenerateCloudsTerminateWithoutPlanes) {
  const PlaneRemovalOptions o = SceneOptions();
  const PlaneRemovalResult empty = RemovePlanes(PointCloud{}, o);
  EXPECT_TRUE(empty.planes.empty());
  EXPECT_TRUE(empty.remaining.empty());
  const std::vector<Eigen::Vector3d> one = {{1, 2, 3}};
  EXPECT_TRUE(RemovePlanes(MakeCloud(one), o).planes.empty());
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 200; ++i) line.emplace_back(0.01 * i, 0.02 * i, 5.0);
  const PlaneRemovalResult collinear = RemovePlanes(MakeCloud(line), o);
  EXPECT_TRUE(collinear.planes.empty());
  EXPECT_EQ(collinear.remaining.size(), line.size());
  const std::vector<Eigen::Vector3d> same(100, Eigen::Vector3d(1, 1, 1));
  EXPECT_TRUE(RemovePlanes(MakeCloud(same), o).planes.empty());
}

TEST(RemovePlanes, RejectsBadInput) {
  BoxScene scene = MakeBoxScene(Eigen::Vector3d::Zero());
  PlaneRemovalOptions o = SceneOptions();
  o.distance_threshold_m = 0.0;
  EXPECT_THROW(RemovePlanes(scene.cloud, o), Error);
  o = SceneOptions();
  o.min_fraction = 0.0;
  EXPECT_THROW(RemovePlanes(scene.cloud, o), Error);
  o = SceneOptions();
  o.max_iterations = 0;
  EXPECT_THROW(RemovePlanes(scene.cloud, o), Error);
  o = SceneOptions();
  o.probability = 1.0;
  EXPECT_THROW(RemovePlanes(scene.cloud, o), Error);
  scene.cloud.points[5].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(RemovePlanes(scene.cloud, SceneOptions()), Error);
}

}  // namespace
}  // namespace uwscan::perception
