#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

// The ROS messages uwscan exchanges, in uwscan's own types. Debian's generated ROS message
// headers compile only as C++17 under GCC 12 (DESIGN.md, "Known traps"), so the translation
// units that include them (ros/bridge/*.cpp) are C++17 and see only this header of uwscan's;
// everything else in ros/ works on these types. C++17, no ROS include.
//
// Poses are as uwscan keeps them (T_parent_child, parent and child named by the message); a
// covariance is 6x6 in ROS's order (x, y, z, rotation about x, y, z, in the parent frame).
namespace uwscan::ros {

using Covariance6d = Eigen::Matrix<double, 6, 6>;

struct Header {
  double stamp_s = 0.0;  // ROS time, seconds
  std::string frame_id;
};

// sensor_msgs/Image.
struct ImageMessage {
  Header header;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint32_t step = 0;  // bytes per row
  std::string encoding;    // "mono8", "mono16", ...
  bool big_endian = false;
  std::vector<std::uint8_t> data;
};

// nav_msgs/Odometry (the twist is not used by uwscan and is written as zero).
struct OdometryMessage {
  Header header;               // frame_id: the navigation's world ("odom")
  std::string child_frame_id;  // the vehicle ("base_link")
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // T_header_child
  Covariance6d pose_covariance = Covariance6d::Zero();
};

// geometry_msgs/TransformStamped.
struct TransformMessage {
  Header header;
  std::string child_frame_id;
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // T_header_child
};

// geometry_msgs/PoseWithCovarianceStamped.
struct PoseMessage {
  Header header;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Covariance6d covariance = Covariance6d::Zero();
};

// sensor_msgs/PointCloud2 with float32 fields x, y, z (and a float32 field of `scalar_name`
// when `scalars` is not empty, one per point).
struct CloudMessage {
  Header header;
  std::vector<Eigen::Vector3f> points;
  std::string scalar_name;
  std::vector<float> scalars;
};

// nav_msgs/Path: poses in header.frame_id, each with its own stamp.
struct PathMessage {
  Header header;
  std::vector<double> stamps_s;
  std::vector<Eigen::Isometry3d> poses;
};

// geometry_msgs/PoseArray.
struct PoseArrayMessage {
  Header header;
  std::vector<Eigen::Isometry3d> poses;
};

// visualization_msgs/Marker, the kinds uwscan draws.
struct MarkerMessage {
  enum class Kind { kPoints, kText, kDeleteAll };
  Header header;
  std::string ns;
  int id = 0;
  Kind kind = Kind::kPoints;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3f> points;  // kPoints, in the marker's pose
  std::string text;                     // kText
  double scale_m = 0.005;               // point size, or text height
  Eigen::Vector4f rgba = {1.0F, 1.0F, 1.0F, 1.0F};
};

// std_msgs/String.
struct StringMessage {
  std::string data;
};

}  // namespace uwscan::ros
