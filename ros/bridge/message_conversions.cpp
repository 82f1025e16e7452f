#include "ros/bridge/message_conversions.hpp"

#include <cmath>
#include <cstring>
#include <limits>

#include "ros/bridge/pose_checks.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

std_msgs::Header ToRos(const Header& header) {
  std_msgs::Header h;
  h.stamp = ToRosTime(header.stamp_s);
  h.frame_id = header.frame_id;
  return h;
}

Header FromRos(const std_msgs::Header& header) { return {header.stamp.toSec(), header.frame_id}; }

geometry_msgs::Pose ToRosPose(const Eigen::Isometry3d& T) {
  geometry_msgs::Pose p;
  const Eigen::Quaterniond q(T.rotation());
  p.position.x = T.translation().x();
  p.position.y = T.translation().y();
  p.position.z = T.translation().z();
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  p.orientation.w = q.w();
  return p;
}

Eigen::Isometry3d FromRosPose(const geometry_msgs::Pose& p, const std::string& what) {
  return PoseFromRosValues(p.position.x, p.position.y, p.position.z, p.orientation.x,
                           p.orientation.y, p.orientation.z, p.orientation.w, what);
}

Covariance6d FromRosCovariance(const boost::array<double, 36>& c, const std::string& what) {
  return CovarianceFromRosValues(c.data(), what);
}

boost::array<double, 36> ToRosCovariance(const Covariance6d& m) {
  boost::array<double, 36> c{};
  for (int i = 0; i < 36; ++i) c[i] = m(i / 6, i % 6);
  return c;
}

}  // namespace

::ros::Time ToRosTime(double stamp_s) {
  if (!std::isfinite(stamp_s) || stamp_s < 0.0 || stamp_s >= 4294967295.0) {
    throw Error("stamp " + std::to_string(stamp_s) + " s is outside ROS time's range [0, 2^32) s");
  }
  ::ros::Time t;
  t.fromSec(stamp_s);
  return t;
}

ImageMessage FromRos(const sensor_msgs::Image& m) {
  ImageMessage out;
  out.header = FromRos(m.header);
  out.width = m.width;
  out.height = m.height;
  out.step = m.step;
  out.encoding = m.encoding;
  out.big_endian = m.is_bigendian != 0;
  out.data = m.data;
  return out;
}

sensor_msgs::Image ToRos(const ImageMessage& m) {
  sensor_msgs::Image out;
  out.header = ToRos(m.header);
  out.width = m.width;
  out.height = m.height;
  out.step = m.step;
  out.encoding = m.encoding;
  out.is_bigendian = m.big_endian ? 1 : 0;
  out.data = m.data;
  return out;
}

OdometryMessage FromRos(const nav_msgs::Odometry& m) {
  OdometryMessage out;
  out.header = FromRos(m.header);
  out.child_frame_id = m.child_frame_id;
  out.pose = FromRosPose(m.pose.pose, "nav_msgs/Odometry pose");
  out.pose_covariance = FromRosCovariance(m.pose.covariance, "nav_msgs/Odometry pose");
  return out;
}

nav_msgs::Odometry ToRos(const OdometryMessage& m) {
  nav_msgs::Odometry out;
  out.header = ToRos(m.header);
  out.child_frame_id = m.child_frame_id;
  out.pose.pose = ToRosPose(m.pose);
  out.pose.covariance = ToRosCovariance(m.pose_covariance);
  return out;
}

TransformMessage FromRos(const geometry_msgs::TransformStamped& m) {
  TransformMessage out;
  out.header = FromRos(m.header);
  out.child_frame_id = m.child_frame_id;
  const auto& t = m.transform.translation;
  const auto& q = m.transform.rotation;
  out.transform = PoseFromRosValues(t.x, t.y, t.z, q.x, q.y, q.z, q.w,
                                    "transform " + m.header.frame_id + " -> " + m.child_frame_id);
  return out;
}

geometry_msgs::TransformStamped ToRos(const TransformMessage& m) {
  geometry_msgs::TransformStamped out;
  out.header = ToRos(m.header);
  out.child_frame_id = m.child_frame_id;
  const geometry_msgs::Pose p = ToRosPose(m.transform);
  out.transform.translation.x = p.position.x;
  out.transform.translation.y = p.position.y;
  out.transform.translation.z = p.position.z;
  out.transform.rotation = p.orientation;
  return out;
}

std::vector<TransformMessage> FromRos(const tf2_msgs::TFMessage& m) {
  std::vector<TransformMessage> out;
  out.reserve(m.transforms.size());
  for (const geometry_msgs::TransformStamped& t : m.transforms) out.push_back(FromRos(t));
  return out;
}

tf2_msgs::TFMessage ToRos(const std::vector<TransformMessage>& transforms) {
  tf2_msgs::TFMessage out;
  for (const TransformMessage& t : transforms) out.transforms.push_back(ToRos(t));
  return out;
}

sensor_msgs::PointCloud2 ToRos(const CloudMessage& m) {
  sensor_msgs::PointCloud2 out;
  out.header = ToRos(m.header);
  const bool with_scalar = !m.scalars.empty();
  if (with_scalar && m.scalars.size() != m.points.size()) {
    throw Error("cloud " + m.header.frame_id + ": " + std::to_string(m.scalars.size()) +
                " values of '" + m.scalar_name + "' for " + std::to_string(m.points.size()) +
                " points");
  }
  std::vector<std::string> names = {"x", "y", "z"};
  if (with_scalar) names.push_back(m.scalar_name);
  for (std::size_t i = 0; i < names.size(); ++i) {
    sensor_msgs::PointField f;
    f.name = names[i];
    f.offset = static_cast<std::uint32_t>(4 * i);
    f.datatype = sensor_msgs::PointField::FLOAT32;
    f.count = 1;
    out.fields.push_back(f);
  }
  out.height = 1;
  out.width = static_cast<std::uint32_t>(m.points.size());
  out.point_step = static_cast<std::uint32_t>(4 * names.size());
  out.row_step = out.point_step * out.width;
  out.is_bigendian = 0;
  out.is_dense = 1;
  out.data.resize(static_cast<std::size_t>(out.row_step));
  std::uint8_t* dst = out.data.data();
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    std::memcpy(dst, m.points[i].data(), 12);
    if (with_scalar) std::memcpy(dst + 12, &m.scalars[i], 4);
    dst += out.point_step;
  }
  return out;
}

CloudMessage FromRos(const sensor_msgs::PointCloud2& m) {
  CloudMessage out;
  out.header = FromRos(m.header);
  const std::string what = "sensor_msgs/PointCloud2 in " + m.header.frame_id;
  if (m.is_bigendian != 0) throw Error(what + ": big-endian clouds are not read");
  std::uint32_t offsets[3] = {};
  bool doubles[3] = {};
  const char* names[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    bool found = false;
    for (const sensor_msgs::PointField& f : m.fields) {
      if (f.name != names[k]) continue;
      if (f.datatype != sensor_msgs::PointField::FLOAT32 &&
          f.datatype != sensor_msgs::PointField::FLOAT64) {
        throw Error(what + ": field " + f.name + " is neither float32 nor float64");
      }
      offsets[k] = f.offset;
      doubles[k] = f.datatype == sensor_msgs::PointField::FLOAT64;
      found = true;
    }
    if (!found) throw Error(what + ": no field " + names[k]);
  }
  const std::size_t points = static_cast<std::size_t>(m.width) * m.height;
  if (m.data.size() < static_cast<std::size_t>(m.row_step) * m.height ||
      m.row_step < m.point_step * m.width || (points > 0 && m.point_step < 12)) {
    throw Error(what + ": data of " + std::to_string(m.data.size()) + " bytes does not hold " +
                std::to_string(points) + " points");
  }
  for (std::uint32_t row = 0; row < m.height; ++row) {
    for (std::uint32_t col = 0; col < m.width; ++col) {
      const std::uint8_t* p = m.data.data() + static_cast<std::size_t>(row) * m.row_step +
                              static_cast<std::size_t>(col) * m.point_step;
      Eigen::Vector3f v;
      for (int k = 0; k < 3; ++k) {
        if (doubles[k]) {
          double d = 0.0;
          std::memcpy(&d, p + offsets[k], 8);
          v[k] = static_cast<float>(d);
        } else {
          std::memcpy(&v[k], p + offsets[k], 4);
        }
      }
      if (v.allFinite()) out.points.push_back(v);
    }
  }
  return out;
}

nav_msgs::Path ToRos(const PathMessage& m) {
  nav_msgs::Path out;
  out.header = ToRos(m.header);
  for (std::size_t i = 0; i < m.poses.size(); ++i) {
    geometry_msgs::PoseStamped p;
    p.header = ToRos(Header{m.stamps_s.at(i), m.header.frame_id});
    p.pose = ToRosPose(m.poses[i]);
    out.poses.push_back(p);
  }
  return out;
}

geometry_msgs::PoseWithCovarianceStamped ToRos(const PoseMessage& m) {
  geometry_msgs::PoseWithCovarianceStamped out;
  out.header = ToRos(m.header);
  out.pose.pose = ToRosPose(m.pose);
  out.pose.covariance = ToRosCovariance(m.covariance);
  return out;
}

geometry_msgs::PoseArray ToRos(const PoseArrayMessage& m) {
  geometry_msgs::PoseArray out;
  out.header = ToRos(m.header);
  for (const Eigen::Isometry3d& T : m.poses) out.poses.push_back(ToRosPose(T));
  return out;
}

visualization_msgs::MarkerArray ToRos(const std::vector<MarkerMessage>& markers) {
  visualization_msgs::MarkerArray out;
  for (const MarkerMessage& m : markers) {
    visualization_msgs::Marker v;
    v.header = ToRos(m.header);
    v.ns = m.ns;
    v.id = m.id;
    v.pose = ToRosPose(m.pose);
    v.color.r = m.rgba[0];
    v.color.g = m.rgba[1];
    v.color.b = m.rgba[2];
    v.color.a = m.rgba[3];
    switch (m.kind) {
      case MarkerMessage::Kind::kPoints:
        v.type = visualization_msgs::Marker::POINTS;
        v.action = visualization_msgs::Marker::ADD;
        v.scale.x = v.scale.y = m.scale_m;
        for (const Eigen::Vector3f& p : m.points) {
          geometry_msgs::Point q;
          q.x = p.x();
          q.y = p.y();
          q.z = p.z();
          v.points.push_back(q);
        }
        break;
      case MarkerMessage::Kind::kText:
        v.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
        v.action = visualization_msgs::Marker::ADD;
        v.scale.z = m.scale_m;
        v.text = m.text;
        break;
      case MarkerMessage::Kind::kDeleteAll:
        v.action = visualization_msgs::Marker::DELETEALL;
        break;
    }
    out.markers.push_back(v);
  }
  return out;
}

StringMessage FromRos(const std_msgs::String& m) { return {m.data}; }

std_msgs::String ToRos(const StringMessage& m) {
  std_msgs::String out;
  out.data = m.data;
  return out;
}

}  // namespace uwscan::ros
