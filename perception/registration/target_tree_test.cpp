#include "perception/registration/target_tree.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "perception/cloud/flann_distance.hpp"

namespace uwscan::perception {
namespace {

// Every point searched: FLANN's float distance, strictly within the radius, the lowest index
// among equally near points that pass `accept`.
template <typename Accept>
int BruteNearest(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& q,
                 float radius_sq, Accept accept) {
  float best = radius_sq;
  int found = kNoMatch;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    const float d = FlannSquaredDistance(q.x(), q.y(), q.z(), p.x(), p.y(), p.z());
    if (d < best && accept(i)) {
      best = d;
      found = static_cast<int>(i);
    }
  }
  return found;
}

// How many points lie exactly as far from q as points[index] (itself included).
int EquallyNear(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& q, int index) {
  const auto distance = [&](const Eigen::Vector3f& p) {
    return FlannSquaredDistance(q.x(), q.y(), q.z(), p.x(), p.y(), p.z());
  };
  const float d = distance(points[static_cast<std::size_t>(index)]);
  int count = 0;
  for (const Eigen::Vector3f& p : points) count += distance(p) == d ? 1 : 0;
  return count;
}

// A wavy sheet sampled on a jittered grid (a voxelised submap), with every tenth point written
// twice and some points on a lattice, so that equally near points are common.
PointCloud Sheet(std::mt19937& rng) {
  std::uniform_real_distribution<float> jitter(-0.002f, 0.002f);
  PointCloud cloud;
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 40; ++j) {
      const float x = 0.01f * static_cast<float>(i);
      const float y = 0.01f * static_cast<float>(j);
      const bool lattice = (i + j) % 3 == 0;
      const float dx = lattice ? 0.0f : jitter(rng);
      const float dy = lattice ? 0.0f : jitter(rng);
      cloud.points.emplace_back(x + dx, y + dy, lattice ? 0.0f : 0.02f * std::sin(8.0f * x));
      if ((i * 40 + j) % 10 == 0) cloud.points.push_back(cloud.points.back());
    }
  }
  for (const Eigen::Vector3f& p : cloud.points) {
    cloud.normals.push_back(
        Eigen::Vector3f(-0.16f * std::cos(8.0f * p.x()), 0.0f, 1.0f).normalized());
  }
  return cloud;
}

// Queries near the sheet, on its lattice points, and exactly between two of them.
std::vector<Eigen::Vector3f> Queries(std::mt19937& rng) {
  std::uniform_real_distribution<float> x(-0.05f, 0.65f), y(-0.05f, 0.45f), z(-0.03f, 0.03f);
  std::vector<Eigen::Vector3f> queries;
  for (int i = 0; i < 3000; ++i) queries.emplace_back(x(rng), y(rng), z(rng));
  for (int i = 0; i < 57; i += 3) queries.emplace_back(0.01f * i + 0.005f, 0.0f, 0.0f);
  for (int i = 0; i < 57; i += 3) queries.emplace_back(0.01f * i, 0.0f, 0.001f);
  return queries;
}

TEST(TargetTree, FindsTheNearestPointOfAllWithTheLowestIndexAmongEquals) {
  std::mt19937 rng(7);
  const PointCloud target = Sheet(rng);
  const TargetTree tree(target, 0.0, 0.0, 2);
  NearestWithin result;
  result.Gate(nullptr, Eigen::Vector3f::Zero(), -1.0f);
  int found = 0, tied = 0;
  for (const float radius : {0.004f, 0.01f, 0.05f}) {
    for (const Eigen::Vector3f& q : Queries(rng)) {
      const int expected =
          BruteNearest(target.points, q, radius * radius, [](std::size_t) { return true; });
      ASSERT_EQ(tree.Nearest(q.cast<double>(), radius * radius, result), expected)
          << "query " << q.transpose() << ", radius " << radius;
      if (expected == kNoMatch) continue;
      ++found;
      tied += EquallyNear(target.points, q, expected) > 1 ? 1 : 0;
    }
  }
  EXPECT_GT(found, 3000);  // queries with an answer and without
  EXPECT_LT(found, 9000);
  EXPECT_GT(tied, 100);  // and answers among equally near points
}

TEST(TargetTree, HonoursTheNormalGate) {
  std::mt19937 rng(8);
  const PointCloud target = Sheet(rng);
  const TargetTree tree(target, 0.0, 0.0, 2);
  const Eigen::Vector3f query_normal = Eigen::Vector3f(0.1f, 0.0f, 1.0f).normalized();
  const float min_cos = std::cos(0.08f);
  NearestWithin result;
  result.Gate(&target.normals, query_normal, min_cos);
  const auto accept = [&](std::size_t i) { return target.normals[i].dot(query_normal) >= min_cos; };
  for (const Eigen::Vector3f& q : Queries(rng)) {
    ASSERT_EQ(tree.Nearest(q.cast<double>(), 0.02f * 0.02f, result),
              BruteNearest(target.points, q, 0.02f * 0.02f, accept));
  }
}

TEST(TargetTree, AnswersAlikeOnOneThreadAndTwoAndOnATinyTarget) {
  std::mt19937 rng(9);
  const PointCloud target = Sheet(rng);
  const TargetTree one(target, 0.0, 0.0, 1);
  const TargetTree two(target, 0.0, 0.0, 2);
  NearestWithin a, b;
  for (const Eigen::Vector3f& q : Queries(rng)) {
    ASSERT_EQ(one.Nearest(q.cast<double>(), 1e-4f, a), two.Nearest(q.cast<double>(), 1e-4f, b));
  }
  PointCloud tiny;
  tiny.points = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}};
  const TargetTree small(tiny, 0.0, 0.0, 2);
  EXPECT_EQ(small.Nearest({0.9, 0.0, 0.0}, 1.0f, a), 1);
  EXPECT_EQ(small.Nearest({0.1, 0.0, 0.0}, 1.0f, a), 0);
  EXPECT_EQ(small.Nearest({5.0, 0.0, 0.0}, 1.0f, a), kNoMatch);
}

}  // namespace
}  // namespace uwscan::perception
