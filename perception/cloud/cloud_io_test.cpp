#include "perception/cloud/cloud_io.hpp"

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include "perception/cloud/pcd_reader.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/ply_reader.hpp"
#include "scanner/common/random_draws.hpp"

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
      points.push_back(offset + Eigen::Vector3d{u(rng), u(rng), u(rng)});
    PointCloud cloud = MakeCloud(points);
    if (normals) {
      for (int i = 0; i < 500; ++i) {
        cloud.normals.push_back(DrawVector3(u, rng).cast<float>().normalized());
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
  std::ofstream(path) << "# x y z r g b\n1 2 3 0 0 0 # the first\n\n4.5, 5.5, 6.5 200 100 50\r\n"
                         "nan 1 1 0 0 0\n+7 -8 9e0 1 1 1\n";
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

TEST_F(CloudIoTest, ASensorPoseWrittenToAPcdIsReadBackFromItsViewpoint) {
  const PointCloud cloud =
      MakeCloud(std::vector<Eigen::Vector3d>{{0, 0, 1}, {0.1, 0, 1}, {0, 0.1, 1.2}});
  Eigen::Isometry3d T_file_sensor = Eigen::Isometry3d::Identity();
  T_file_sensor.linear() = Eigen::AngleAxisd(3.0, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  T_file_sensor.translation() = Eigen::Vector3d(0.5, -0.25, 2.0);
  for (const bool binary : {true, false}) {
    const fs::path path = dir_ / (binary ? "viewpoint.pcd" : "viewpoint_ascii.pcd");
    WriteCloud(path, cloud, binary, T_file_sensor);
    CloudReadStats stats;
    ReadCloud(path, &stats);
    ASSERT_TRUE(stats.T_file_sensor.has_value()) << stats.viewpoint_error;
    // PCL writes the VIEWPOINT's numbers with six significant digits.
    EXPECT_LT((stats.T_file_sensor->matrix() - T_file_sensor.matrix()).norm(), 1e-5) << binary;
  }
  EXPECT_THROW(WriteCloud(dir_ / "viewpoint.ply", cloud, true, T_file_sensor), Error);
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
  EXPECT_NE(MessageOf([&] { ReadCloud(empty); }).find("(read as XYZ): no point"),
            std::string::npos);
  // A line with other columns than the first point's is damage (a line cut short), not a point.
  const fs::path ragged = dir_ / "ragged.xyz";
  std::ofstream(ragged) << "1 2 3 200 100 50\n4 5 6 200 100 50\n7 8 9 200\n";
  const std::string ragged_message = MessageOf([&] { ReadCloud(ragged); });
  EXPECT_NE(ragged_message.find("(read as XYZ) line 3: 4 columns where line 1 has 6"),
            std::string::npos)
      << ragged_message;
  const fs::path word = dir_ / "word.xyz";
  std::ofstream(word) << "1 2 3\n4 5 6 abc\n";
  EXPECT_NE(MessageOf([&] { ReadCloud(word); }).find("line 2"), std::string::npos);
  // A mesh given where a cloud is read is named as one.
  const fs::path mesh = dir_ / "part.obj";
  std::ofstream(mesh) << "v 0 0 0\n";
  EXPECT_NE(MessageOf([&] { ReadCloud(mesh); }).find("an OBJ file is a mesh, not a point cloud"),
            std::string::npos);
  const fs::path all_nan = dir_ / "nan.xyz";
  std::ofstream(all_nan) << "nan 0 0\n0 inf 0\n";
  const std::string nan_message = MessageOf([&] { ReadCloud(all_nan); });
  EXPECT_NE(nan_message.find("(read as XYZ) holds no finite point"), std::string::npos);
  EXPECT_NE(nan_message.find("2 dropped"), std::string::npos);
  const fs::path text = dir_ / "out.xyz";
  EXPECT_NE(MessageOf([&] {
              WriteCloud(text, RandomCloud(Eigen::Vector3d::Zero(), false));
            }).find(text.string()),
            std::string::npos);
}

// A cloud's file damaged where the cloud does not look (its faces) or in a word of its text is
// refused with what is wrong, not read as if whole.
TEST_F(CloudIoTest, DamageIsNamedWhereverItIs) {
  const fs::path faces = dir_ / "faces.ply";
  std::ofstream(faces) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                          "property float y\nproperty float z\nelement face 1\n"
                          "property list uchar int vertex_indices\nend_header\n"
                          "0 0 0\n1 0 0\n0 1 0\n3 0 1 999\n";
  const std::string face_message = MessageOf([&] { ReadCloud(faces); });
  EXPECT_NE(face_message.find("(read as PLY): element face row 0: names vertex 999 of 3"),
            std::string::npos)
      << face_message;
  const fs::path word = dir_ / "word.ply";
  std::ofstream(word) << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                         "property float y\nproperty float z\nend_header\n0 0 0\n1 abc 0\n";
  const std::string word_message = MessageOf([&] { ReadCloud(word); });
  EXPECT_NE(word_message.find("element vertex row 1: y: 'abc' is not a number"), std::string::npos)
      << word_message;
  std::ofstream(word) << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                         "property float y\nproperty float z\nend_header\n0 0 0\n1 2      \n";
  EXPECT_NE(MessageOf([&] { ReadCloud(word); }).find("z: the file ends"), std::string::npos);
  const fs::path no_data = dir_ / "no_data.pcd";
  std::ofstream(no_data) << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                            "WIDTH 1\nHEIGHT 1\nPOINTS 1\n1 2 3\n";
  EXPECT_NE(MessageOf([&] { ReadCloud(no_data); }).find("no DATA line"), std::string::npos);
  const fs::path fifo = dir_ / "pipe.pcd";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(MessageOf([&] { ReadCloud(fifo); }).find("not a regular file"), std::string::npos);
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

// uwscan's own PLY and PCD readers against files written by PCL's writers (the independent
// reference), in every encoding, and their refusals of broken files: one error, no output.

class CloudReadersTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("uwscan_cloud_readers_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    cloud_.width = 37;
    cloud_.height = 3;  // organised: rows are read in order
    for (int i = 0; i < 37 * 3; ++i) {
      pcl::PointNormal p;
      p.x = u(rng);
      p.y = u(rng);
      p.z = 5.0f + u(rng);
      const Eigen::Vector3f n = Eigen::Vector3f{u(rng), u(rng), u(rng)}.normalized();
      p.normal_x = n.x();
      p.normal_y = n.y();
      p.normal_z = n.z();
      p.curvature = 0.5f;
      cloud_.push_back(p);
    }
    cloud_.width = 37;
    cloud_.height = 3;
  }
  void TearDown() override { fs::remove_all(dir_); }

  void ExpectSamePoints(const std::vector<Eigen::Vector3d>& points,
                        const std::vector<Eigen::Vector3d>& normals) {
    ASSERT_EQ(points.size(), cloud_.size());
    ASSERT_EQ(normals.size(), cloud_.size());
    for (std::size_t i = 0; i < cloud_.size(); ++i) {
      // float32 in the file: bit for bit when binary, to the 8 digits PCL prints in ascii.
      EXPECT_NEAR(points[i].x(), cloud_[i].x, 1e-6) << i;
      EXPECT_NEAR(points[i].y(), cloud_[i].y, 1e-6) << i;
      EXPECT_NEAR(points[i].z(), cloud_[i].z, 1e-6) << i;
      EXPECT_NEAR(normals[i].z(), cloud_[i].normal_z, 1e-6) << i;
    }
  }

  fs::path dir_;
  pcl::PointCloud<pcl::PointNormal> cloud_;
};

TEST_F(CloudReadersTest, ReadsEveryPcdEncodingPclWrites) {
  pcl::PCDWriter writer;
  const fs::path ascii = dir_ / "a.pcd", binary = dir_ / "b.pcd", compressed = dir_ / "c.pcd";
  ASSERT_EQ(writer.writeASCII(ascii.string(), cloud_, 8), 0);
  ASSERT_EQ(writer.writeBinary(binary.string(), cloud_), 0);
  ASSERT_EQ(writer.writeBinaryCompressed(compressed.string(), cloud_), 0);
  for (const fs::path& path : {ascii, binary, compressed}) {
    SCOPED_TRACE(path.filename().string());
    const PcdContent content = ReadPcd(path);
    ExpectSamePoints(content.points, content.normals);
  }
}

TEST_F(CloudReadersTest, ReadsPlyPclWritesAndFacesOfAnyPolygon) {
  pcl::PLYWriter writer;
  const fs::path binary = dir_ / "b.ply", ascii = dir_ / "a.ply";
  ASSERT_EQ(writer.write(binary.string(), cloud_, true, false), 0);
  ASSERT_EQ(writer.write(ascii.string(), cloud_, false, false), 0);
  for (const fs::path& path : {binary, ascii}) {
    SCOPED_TRACE(path.filename().string());
    const scanner::PlyContent content = scanner::ReadPly(path, false);
    // PCL's ascii PLY keeps 6 significant digits.
    const double tolerance = path == ascii ? 1e-5 : 0.0;
    ASSERT_EQ(content.vertices.size(), cloud_.size());
    for (std::size_t i = 0; i < cloud_.size(); ++i) {
      EXPECT_NEAR(content.vertices[i].x(), cloud_[i].x, tolerance + 1e-7);
      EXPECT_NEAR(content.normals[i].y(), cloud_[i].normal_y, tolerance + 1e-7);
    }
  }

  // Big-endian binary with a quad and a triangle, a list of uchar counts and int indices.
  const fs::path mesh = dir_ / "quad.ply";
  {
    std::ofstream out(mesh, std::ios::binary);
    out << "ply\nformat binary_big_endian 1.0\ncomment made by hand\nelement vertex 4\n"
           "property double x\nproperty double y\nproperty double z\nelement face 2\n"
           "property list uchar int vertex_indices\nend_header\n";
    auto put_be = [&out](auto value) {
      char bytes[sizeof(value)];
      std::memcpy(bytes, &value, sizeof(value));
      for (int b = int(sizeof(value)) - 1; b >= 0; --b) out.put(bytes[b]);
    };
    for (double v : {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.25}) put_be(v);
    out.put(4);
    for (std::int32_t i : {0, 1, 2, 3}) put_be(i);
    out.put(3);
    for (std::int32_t i : {0, 2, 3}) put_be(i);
  }
  const scanner::PlyContent quad = scanner::ReadPly(mesh, true);
  ASSERT_EQ(quad.vertices.size(), 4u);
  EXPECT_EQ(quad.vertices[3], Eigen::Vector3d(0.0, 1.0, 0.25));
  ASSERT_EQ(quad.triangles.size(), 3u);  // the quad fanned into two, then the triangle
  EXPECT_EQ(quad.triangles[1], Eigen::Vector3i(0, 2, 3));
}

// Intensities as PCL writes them (PointXYZI, float32 "intensity"), and CloudCompare's
// "scalar_Intensity" PLY property, reach the cloud point for point; uwscan's writer keeps them.
TEST_F(CloudReadersTest, ReadsIntensityFromPclPcdAndPlyAndKeepsItOnWrite) {
  pcl::PointCloud<pcl::PointXYZI> with_intensity;
  for (std::size_t i = 0; i < cloud_.size(); ++i) {
    pcl::PointXYZI p;
    p.x = cloud_[i].x;
    p.y = cloud_[i].y;
    p.z = cloud_[i].z;
    p.intensity = 10.0f + 0.5f * static_cast<float>(i);
    with_intensity.push_back(p);
  }
  const fs::path pcd = dir_ / "i.pcd", ply = dir_ / "i.ply";
  ASSERT_EQ(pcl::PCDWriter().writeBinaryCompressed(pcd.string(), with_intensity), 0);
  ASSERT_EQ(pcl::PLYWriter().write(ply.string(), with_intensity, true, false), 0);
  for (const fs::path& path : {pcd, ply}) {
    SCOPED_TRACE(path.filename().string());
    const PointCloud read = ReadCloud(path);
    ASSERT_TRUE(read.has_intensity());
    for (std::size_t i = 0; i < with_intensity.size(); ++i) {
      EXPECT_EQ(read.intensity[i], with_intensity[i].intensity) << i;
    }
    const fs::path again = dir_ / ("again" + path.extension().string());
    WriteCloud(again, read, /*binary=*/false);
    EXPECT_EQ(ReadCloud(again).intensity, read.intensity);
  }

  const fs::path cloud_compare = dir_ / "cc.ply";
  {
    std::ofstream out(cloud_compare);
    out << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty "
           "float z\n"
           "property float scalar_Intensity\nend_header\n0 0 1 0.25\n1 0 1 nan\n";
  }
  const PointCloud cc = ReadCloud(cloud_compare);
  ASSERT_EQ(cc.intensity.size(), 2u);
  EXPECT_EQ(cc.intensity[0], 0.25f);
  EXPECT_TRUE(std::isnan(cc.intensity[1]));  // no value: the point stays, its intensity is NaN
  const fs::path plain = dir_ / "plain.ply";
  ASSERT_EQ(pcl::PLYWriter().write(plain.string(), cloud_, true, false), 0);
  EXPECT_FALSE(ReadCloud(plain).has_intensity());
}

TEST_F(CloudReadersTest, BrokenFilesGiveOneErrorAndPrintNothing) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"empty.pcd", ""},
      {"noheader.pcd", "1 2 3\n4 5 6\n"},
      {"huge.pcd",
       "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4000000000\nHEIGHT 1\nDATA binary\n\x01\x02"},
      {"short.pcd",
       "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nDATA ascii\n1 2 3\n4 "
       "5\n"},
      {"mismatch.pcd", "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n"},
      {"noxyz.pcd", "FIELDS a b\nSIZE 4 4\nTYPE F F\nWIDTH 1\nDATA ascii\n1 2\n"},
      {"empty.ply", ""},
      {"noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"},
      {"huge.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\nproperty float x\n"
       "property float y\nproperty float z\nend_header\n\x01"},
      {"badtype.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n1\n"},
      {"cut.ply",
       "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n1 2 3\n4\n"},
      {"cut.xyz", "1 2 3\n4 5\n"},
  };
  for (const auto& [name, text] : files) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    testing::internal::CaptureStderr();
    testing::internal::CaptureStdout();
    std::string message;
    try {
      ReadCloud(path);
    } catch (const Error& e) {
      message = e.what();
    }
    const std::string printed =
        testing::internal::GetCapturedStderr() + testing::internal::GetCapturedStdout();
    EXPECT_NE(message.find(path.string()), std::string::npos) << name << ": '" << message << "'";
    // ... and the format it was read as, where the reader got that far (an empty file is refused
    // before any reader sees it).
    if (!text.empty()) {
      const std::string extension = path.extension().string();
      const std::string format = extension == ".pcd"   ? "read as PCD"
                                 : extension == ".ply" ? "read as PLY"
                                                       : "read as XYZ";
      EXPECT_NE(message.find(format), std::string::npos) << name << ": '" << message << "'";
    }
    EXPECT_EQ(message.find('\n'), std::string::npos) << name;
    EXPECT_EQ(printed, "") << name;
  }
}

}  // namespace
}  // namespace uwscan::perception
