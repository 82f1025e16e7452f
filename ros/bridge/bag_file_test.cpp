#include "ros/bridge/bag_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

std::filesystem::path Scratch(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("uwscan_bag_file_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::remove(dir / name);
  return dir / name;
}

Eigen::Isometry3d Pose(double x, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, 2.0, -3.0);
  return T;
}

TEST(BagFile, WritesAndReadsBackEveryMessageUwscanReads) {
  const std::filesystem::path path = Scratch("round_trip.bag");
  {
    BagWriter bag(path.string());
    bag.Write("/dive", StringMessage{"uwscan_format: 1"}, 100.0, true);
    TransformMessage mount;
    mount.header = {100.0, "base_link"};
    mount.child_frame_id = "camera";
    mount.transform = Pose(0.3, 0.1);
    bag.Write("/tf_static", std::vector<TransformMessage>{mount}, 100.0);
    for (int i = 0; i < 5; ++i) {
      ImageMessage image;
      image.header = {100.0 + 0.01 * i, "camera"};
      image.width = 4;
      image.height = 2;
      image.step = 8;
      image.encoding = "mono16";
      image.data.assign(16, static_cast<std::uint8_t>(i));
      bag.Write("/frames", image);
      OdometryMessage odometry;
      odometry.header = {100.0 + 0.01 * i + 0.005, "odom"};
      odometry.child_frame_id = "base_link";
      odometry.pose = Pose(i, 0.2 * i);
      odometry.pose_covariance = Covariance6d::Identity() * (i + 1);
      bag.Write("/odometry", odometry);
    }
    bag.Close();
  }
  const BagReader reader(path.string());
  const std::vector<BagTopic> topics = reader.Topics();
  ASSERT_EQ(topics.size(), 4u);
  for (const BagTopic& t : topics) {
    if (t.name == "/frames") {
      EXPECT_EQ(t.datatype, "sensor_msgs/Image");
      EXPECT_EQ(t.messages, 5);
    }
    if (t.name == "/odometry") {
      EXPECT_EQ(t.datatype, "nav_msgs/Odometry");
    }
  }
  std::vector<double> stamps;
  std::vector<std::string> order;
  BagVisitor visitor;
  visitor.image = [&](const std::string& topic, ImageMessage&& m) {
    order.push_back(topic);
    stamps.push_back(m.header.stamp_s);
    EXPECT_EQ(m.data, std::vector<std::uint8_t>(16, static_cast<std::uint8_t>(stamps.size() - 1)));
    EXPECT_EQ(m.encoding, "mono16");
  };
  int odometry_seen = 0;
  visitor.odometry = [&](const std::string& topic, OdometryMessage&& m) {
    order.push_back(topic);
    EXPECT_TRUE(m.pose.isApprox(Pose(odometry_seen, 0.2 * odometry_seen), 1e-12));
    EXPECT_EQ(m.pose_covariance(5, 5), odometry_seen + 1);
    EXPECT_EQ(m.child_frame_id, "base_link");
    ++odometry_seen;
  };
  visitor.text = [&](const std::string&, StringMessage&& m) {
    EXPECT_EQ(m.data, "uwscan_format: 1");
  };
  visitor.transforms = [&](const std::string&, std::vector<TransformMessage>&& t) {
    ASSERT_EQ(t.size(), 1u);
    EXPECT_TRUE(t[0].transform.isApprox(Pose(0.3, 0.1), 1e-12));
  };
  reader.Read({"/dive", "/tf_static", "/frames", "/odometry"}, visitor);
  EXPECT_EQ(odometry_seen, 5);
  ASSERT_EQ(stamps.size(), 5u);
  for (int i = 0; i < 5; ++i)
    EXPECT_NEAR(stamps[static_cast<std::size_t>(i)], 100.0 + 0.01 * i, 1e-9);
  // Recorded order: frames and odometry interleave by time.
  ASSERT_EQ(order.size(), 10u);
  for (std::size_t i = 0; i < order.size(); ++i)
    EXPECT_EQ(order[i], i % 2 == 0 ? "/frames" : "/odometry");
  std::filesystem::remove_all(path.parent_path());
}

TEST(BagFile, MissingTruncatedOrForeignFilesAreRefusedByName) {
  const std::filesystem::path missing = Scratch("missing.bag");
  EXPECT_THROW(BagReader(missing.string()), Error);
  const std::filesystem::path text = Scratch("text.bag");
  std::ofstream(text) << "not a bag\n";
  try {
    BagReader reader(text.string());
    FAIL() << "a text file was opened as a bag";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(text.string()), std::string::npos) << e.what();
  }
  const std::filesystem::path existing = Scratch("existing.bag");
  std::ofstream(existing) << "x";
  EXPECT_THROW(BagWriter(existing.string()), Error);
  std::filesystem::remove_all(missing.parent_path());
}

TEST(BagFile, ANanPoseIsRefusedNamingTheTopic) {
  const std::filesystem::path path = Scratch("nan.bag");
  {
    BagWriter bag(path.string());
    OdometryMessage odometry;
    odometry.header = {5.0, "odom"};
    odometry.pose.translation().x() = std::nan("");
    bag.Write("/odometry", odometry);
  }
  const BagReader reader(path.string());
  BagVisitor visitor;
  visitor.odometry = [](const std::string&, OdometryMessage&&) {};
  try {
    reader.Read({"/odometry"}, visitor);
    FAIL() << "a NaN pose was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/odometry"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(path.parent_path());
}

}  // namespace
}  // namespace uwscan::ros
