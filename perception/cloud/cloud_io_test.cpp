#include "perception/cloud/cloud_io.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

namespace fs = std::filesystem;

class CloudIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("uwscan_cloud_io_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static PointCloud RandomCloud(const Eigen::Vector3d& offset, bool normals) {
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 500; ++i)
      points.push_back(offset + Eigen::Vector3d(u(rng), u(rng), u(rng)));
    PointCloud cloud = MakeCloud(points);
    if (normals) {
      for (int i = 0; i < 500; ++i) {
        cloud.normals.push_back(Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized());
      }
    }
    return cloud;
  }

  static void ExpectSameCloud(const PointCloud& a, const PointCloud& b, double tolerance_m) {
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(a.has_normals(), b.has_normals());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_LT((a.Point(i) - b.Point(i)).norm(), tolerance_m) << i;
      if (a.has_normals()) {
        EXPECT_LT((a.normals[i] - b.normals[i]).norm(), 1e-6f) << i;
      }
    }
  }

  static std::string MessageOf(const std::function<void()>& f) {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "(no uwscan::Error thrown)";
  }

  fs::path dir_;
};

TEST_F(CloudIoTest, RoundTripPlyAndPcdBinaryAndAscii) {
  const PointCloud cloud = RandomCloud(Eigen::Vector3d(10.0, -20.0, 5.0), true);
  for (const char* name : {"a.ply", "a.pcd"}) {
    for (bool binary : {true, false}) {
      const fs::path path = dir_ / name;
      WriteCloud(path, cloud, binary);
      CloudReadStats stats;
      const PointCloud read = ReadCloud(path, &stats);
      EXPECT_EQ(stats.num_in_file, cloud.size());
      EXPECT_EQ(stats.num_dropped_non_finite, 0u);
      EXPECT_TRUE(stats.has_normals);
      ExpectSameCloud(cloud, read, 1e-5);
      // The origin sits at the centroid, so the float offsets stay small.
      EXPECT_LT((read.origin - Eigen::Vector3d(10.0, -20.0, 5.0)).norm(), 0.2);
    }
  }
  const PointCloud bare = RandomCloud(Eigen::Vector3d::Zero(), false);
  WriteCloud(dir_ / "bare.ply", bare);
  CloudReadStats stats;
  ExpectSameCloud(bare, ReadCloud(dir_ / "bare.ply", &stats), 1e-6);
  EXPECT_FALSE(stats.has_normals);
}

TEST_F(CloudIoTest, HugeCoordinatesKeepTheirPrecision) {
  const PointCloud cloud = RandomCloud(Eigen::Vector3d(4.5e6, 6.1e5, -1e3), false);
  for (const char* name : {"far.ply", "far.pcd"}) {
    WriteCloud(dir_ / name, cloud);
    // float32 would round these coordinates by up to 0.25 m.
    ExpectSameCloud(cloud, ReadCloud(dir_ / name), 1e-6);
  }
}

TEST_F(CloudIoTest, ReadsXyzAndDropsNonFinitePoints) {
  const fs::path path = dir_ / "points.xyz";
  std::ofstream(path) << "# x y z\n1 2 3\n\n4.5, 5.5, 6.5 200 100 50\nnan 1 1\n+7 -8 9e0\n";
  CloudReadStats stats;
  const PointCloud cloud = ReadCloud(path, &stats);
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(stats.num_in_file, 4u);
  EXPECT_EQ(stats.num_dropped_non_finite, 1u);
  EXPECT_LT((cloud.Point(1) - Eigen::Vector3d(4.5, 5.5, 6.5)).norm(), 1e-6);
  EXPECT_LT((cloud.Point(2) - Eigen::Vector3d(7, -8, 9)).norm(), 1e-6);
  EXPECT_LT((cloud.origin - Eigen::Vector3d(12.5, -0.5, 18.5) / 3.0).norm(), 1e-12);

  const fs::path pcd = dir_ / "nan.pcd";
  std::ofstream(pcd) << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                        "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
                        "1 2 3\nnan nan nan\n4 5 6\n";
  const PointCloud from_pcd = ReadCloud(pcd, &stats);
  EXPECT_EQ(from_pcd.size(), 2u);
  EXPECT_EQ(stats.num_dropped_non_finite, 1u);
}

TEST_F(CloudIoTest, NormalsAreMadeUnitAndZeroNormalsDropTheirPoint) {
  const fs::path pcd = dir_ / "normals.pcd";
  std::ofstream(pcd) << "VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\n"
                        "TYPE F F F F F F\nCOUNT 1 1 1 1 1 1\nWIDTH 3\nHEIGHT 1\n"
                        "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
                        "1 2 3 2 0 0\n4 5 6 0 0 0\n7 8 9 0 0.5 0.5\n";
  CloudReadStats stats;
  const PointCloud cloud = ReadCloud(pcd, &stats);
  ASSERT_EQ(cloud.size(), 2u);
  ASSERT_TRUE(cloud.has_normals());
  EXPECT_EQ(stats.num_dropped_non_finite, 1u);
  EXPECT_LT((cloud.normals[0] - Eigen::Vector3f(1, 0, 0)).norm(), 1e-6f);
  EXPECT_NEAR(cloud.normals[1].norm(), 1.0f, 1e-6f);
  EXPECT_LT((cloud.Point(1) - Eigen::Vector3d(7, 8, 9)).norm(), 1e-6);
}

TEST_F(CloudIoTest, ErrorsNameTheFile) {
  const fs::path missing = dir_ / "missing.ply";
  EXPECT_NE(MessageOf([&] { ReadCloud(missing); }).find(missing.string()), std::string::npos);
  const fs::path unknown = dir_ / "cloud.las";
  std::ofstream(unknown) << "x";
  const std::string unknown_message = MessageOf([&] { ReadCloud(unknown); });
  EXPECT_NE(unknown_message.find(unknown.string()), std::string::npos);
  EXPECT_NE(unknown_message.find("extension"), std::string::npos);
  for (const char* name : {"garbage.ply", "garbage.pcd", "garbage.xyz"}) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << "this is not a point cloud\n\x01\x02\x03 garbage\n";
    EXPECT_NE(MessageOf([&] { ReadCloud(path); }).find(path.string()), std::string::npos) << name;
  }
  const fs::path empty = dir_ / "empty.xyz";
  std::ofstream(empty) << "# nothing\n";
  EXPECT_NE(MessageOf([&] { ReadCloud(empty); }).find("no finite point"), std::string::npos);
  const fs::path all_nan = dir_ / "nan.xyz";
  std::ofstream(all_nan) << "nan 0 0\n0 inf 0\n";
  EXPECT_NE(MessageOf([&] { ReadCloud(all_nan); }).find("2 dropped"), std::string::npos);
  const fs::path text = dir_ / "out.xyz";
  EXPECT_NE(MessageOf([&] {
              WriteCloud(text, RandomCloud(Eigen::Vector3d::Zero(), false));
            }).find(text.string()),
            std::string::npos);
}

TEST_F(CloudIoTest, FailedWriteLeavesTheExistingFileIntact) {
  const PointCloud cloud = RandomCloud(Eigen::Vector3d::Zero(), false);
  const fs::path path = dir_ / "keep.ply";
  WriteCloud(path, cloud);
  PointCloud bad = cloud;
  bad.points[7].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(WriteCloud(path, bad), Error);
  EXPECT_THROW(WriteCloud(path, PointCloud{}), Error);
  ExpectSameCloud(cloud, ReadCloud(path), 1e-6);
  // A target that cannot be replaced (a directory): error, and no temporary file left behind.
  const fs::path blocked = dir_ / "blocked.pcd";
  fs::create_directories(blocked / "inside");
  EXPECT_NE(MessageOf([&] { WriteCloud(blocked, cloud); }).find(blocked.string()),
            std::string::npos);
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    (void)entry;
    ++entries;
  }
  EXPECT_EQ(entries, 2u);  // keep.ply and blocked.pcd
}

}  // namespace
}  // namespace uwscan::perception
