#include "perception/preprocessing/voxel_accumulator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/random_draws.hpp"

namespace uwscan::perception {
namespace {

PointCloud RandomCloud(std::uint64_t seed, std::size_t n, const Eigen::Vector3d& origin) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coordinate(-0.3, 0.3);
  PointCloud cloud;
  cloud.origin = origin;
  for (std::size_t i = 0; i < n; ++i)
    cloud.points.push_back(DrawVector3(coordinate, rng).cast<float>());
  return cloud;
}

Eigen::Isometry3d Pose(double angle_rad, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(angle_rad, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// The reference: every cloud moved into one float cloud about the origin, then VoxelDownsample.
TEST(VoxelAccumulator, GivesTheBitsOfVoxelDownsampleOfAllThePointsTogether) {
  const Eigen::Vector3d origin(512.25, -73.5, 9.0);  // far from zero, as a world frame is
  std::vector<PointCloud> clouds;
  std::vector<Eigen::Isometry3d> poses;
  for (int c = 0; c < 5; ++c) {
    clouds.push_back(
        RandomCloud(10 + static_cast<std::uint64_t>(c), 3000, Eigen::Vector3d(0.1 * c, 0, 0)));
    poses.push_back(Pose(0.3 * c, origin + Eigen::Vector3d(0.05 * c, -0.02 * c, 0.01)));
  }
  PointCloud all;
  all.origin = origin;
  VoxelAccumulator accumulator(0.02, origin);
  for (std::size_t c = 0; c < clouds.size(); ++c) {
    const Eigen::Isometry3d T = Eigen::Translation3d(-origin) * poses[c];
    for (std::size_t i = 0; i < clouds[c].size(); ++i)
      all.points.push_back((T * clouds[c].Point(i)).cast<float>());
    accumulator.Add(clouds[c], poses[c]);
  }
  const PointCloud expected = VoxelDownsample(all, {.leaf_m = 0.02});
  const PointCloud merged = accumulator.Cloud();
  EXPECT_EQ(merged.origin, expected.origin);
  ASSERT_EQ(merged.size(), expected.size());
  EXPECT_EQ(accumulator.voxel_count(), expected.size());
  for (std::size_t i = 0; i < merged.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(std::bit_cast<std::uint32_t>(merged.points[i][k]),
                std::bit_cast<std::uint32_t>(expected.points[i][k]))
          << "point " << i;
    }
  }
}

TEST(VoxelAccumulator, RevisitsAddNoVoxels) {
  const PointCloud cloud = RandomCloud(3, 5000, Eigen::Vector3d::Zero());
  VoxelAccumulator accumulator(0.05, Eigen::Vector3d::Zero());
  accumulator.Add(cloud, Eigen::Isometry3d::Identity());
  const std::size_t once = accumulator.voxel_count();
  for (int pass = 0; pass < 20; ++pass) accumulator.Add(cloud, Eigen::Isometry3d::Identity());
  EXPECT_EQ(accumulator.voxel_count(), once);
}

TEST(VoxelAccumulator, RefusesABadLeafAndANonFinitePoint) {
  EXPECT_THROW(VoxelAccumulator(0.0, Eigen::Vector3d::Zero()), Error);
  EXPECT_THROW(VoxelAccumulator(NAN, Eigen::Vector3d::Zero()), Error);
  VoxelAccumulator accumulator(0.01, Eigen::Vector3d::Zero());
  PointCloud bad;
  bad.points.push_back(Eigen::Vector3f(0.0f, NAN, 0.0f));
  EXPECT_THROW(accumulator.Add(bad, Eigen::Isometry3d::Identity()), Error);
}

void ExpectSameBits(const PointCloud& a, const PointCloud& b, const std::string& what) {
  EXPECT_EQ(a.origin, b.origin) << what;
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(std::bit_cast<std::uint32_t>(a.points[i][k]),
                std::bit_cast<std::uint32_t>(b.points[i][k]))
          << what << ", point " << i;
}

// A live map's cycle, many times over: clouds kept for good (in key order), then two nested
// marks with clouds added under each, taken out again newest first, and others added in their
// place. Every state is the map merged from scratch from the same clouds in the same order, to
// the bit.
TEST(VoxelAccumulator, UndoReturnsToEachNestedMarkBitForBit) {
  const Eigen::Vector3d origin(-20.5, 7.25, 3.0);
  std::vector<PointCloud> clouds;
  std::vector<Eigen::Isometry3d> poses;
  for (int c = 0; c < 16; ++c) {
    clouds.push_back(
        RandomCloud(40 + static_cast<std::uint64_t>(c), 4000, Eigen::Vector3d(0.05 * c, 0, 0)));
    poses.push_back(Pose(0.2 * c, origin + Eigen::Vector3d(0.04 * c, 0.01 * c, 0)));
  }
  std::vector<std::size_t> in_map;  // the clouds in the live map, in the order added
  const auto from_scratch = [&] {
    VoxelAccumulator merged(0.02, origin);
    for (const std::size_t c : in_map) merged.Add(clouds[c], poses[c]);
    return merged.Cloud();
  };
  VoxelAccumulator live(0.02, origin);
  const auto add = [&](std::size_t c) {
    live.Add(clouds[c], poses[c]);
    in_map.push_back(c);
  };
  std::size_t kept = 0;
  for (int round = 0; round < 5; ++round) {
    const std::string what = "round " + std::to_string(round);
    add(kept++);
    live.OrderByKey();
    ExpectSameBits(live.Cloud(), from_scratch(), what + ", kept");
    live.Mark();
    add(kept + 2);
    add(kept + 5);
    live.Mark();
    add(kept + 7);
    add(kept);
    ExpectSameBits(live.Cloud(), from_scratch(), what + ", two marks");
    live.Undo();
    in_map.resize(in_map.size() - 2);
    ExpectSameBits(live.Cloud(), from_scratch(), what + ", second mark undone");
    live.Mark();
    add(kept + 9);
    ExpectSameBits(live.Cloud(), from_scratch(), what + ", added again");
    live.Undo();
    live.Undo();
    in_map.resize(kept);
    EXPECT_EQ(live.marks(), 0u);
    ExpectSameBits(live.Cloud(), from_scratch(), what + ", every mark undone");
    EXPECT_EQ(live.voxel_count(), from_scratch().size()) << what;
  }
}

// A live map built into the same cloud again and again as it grows: the same bits as Cloud() each
// time, whatever the cloud held before, and its storage kept while the map grows within the room
// left when it last had to grow.
TEST(VoxelAccumulator, CloudIntoReusesTheCloudItIsGiven) {
  const Eigen::Vector3d origin(3.5, -1.25, 10.0);
  VoxelAccumulator live(0.01, origin);
  PointCloud into;
  into.points.assign(7, Eigen::Vector3f::Ones());
  into.normals.assign(7, Eigen::Vector3f::UnitZ());
  into.intensity.assign(7, 1.0f);
  live.Add(RandomCloud(70, 20000, Eigen::Vector3d::Zero()), Pose(0.1, origin));
  live.CloudInto(into);
  ExpectSameBits(into, live.Cloud(), "first");
  EXPECT_FALSE(into.has_normals());
  EXPECT_FALSE(into.has_intensity());
  // Grown beyond the first map's size: asked for anew, with room for half as much again.
  live.Add(RandomCloud(71, 20000, Eigen::Vector3d(0.7, 0, 0)), Pose(0.2, origin));
  live.CloudInto(into);
  ExpectSameBits(into, live.Cloud(), "grown");
  EXPECT_GE(into.points.capacity(), into.size() + into.size() / 2);
  // Grown within that room: the same storage.
  const Eigen::Vector3f* storage = into.points.data();
  live.Add(RandomCloud(72, 4000, Eigen::Vector3d(0, 0.7, 0)), Pose(0.3, origin));
  live.CloudInto(into);
  ExpectSameBits(into, live.Cloud(), "grown within the room");
  EXPECT_EQ(into.points.data(), storage);
}

}  // namespace
}  // namespace uwscan::perception
