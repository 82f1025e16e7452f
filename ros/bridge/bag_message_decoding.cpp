#include "ros/bridge/bag_message_decoding.hpp"

#include <cstdint>
#include <cstring>

#include "ros/bridge/pose_checks.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

// Reads ROS 1's serialization from a message's bytes; every read is checked against the end.
class SerializedReader {
 public:
  // `type` names the message in errors ("sensor_msgs/Image").
  SerializedReader(std::string_view data, const char* type) : data_(data), type_(type) {}

  template <typename T>
  T Get(const char* field) {
    Need(sizeof(T), field);
    T value;
    std::memcpy(&value, data_.data() + at_,
                sizeof(T));  // ROS 1 and the machines uwscan targets are little-endian
    at_ += sizeof(T);
    return value;
  }
  std::string_view GetBytes(std::size_t length, const char* field) {
    Need(length, field);
    const std::string_view bytes = data_.substr(at_, length);
    at_ += length;
    return bytes;
  }
  std::string GetString(const char* field) {
    return std::string(GetBytes(Get<std::uint32_t>(field), field));
  }
  // An array's length, checked to fit the bytes left at `min_item_bytes` or more per item, so
  // that a damaged length never sizes a container beyond the message.
  std::size_t GetCount(const char* field, std::size_t min_item_bytes) {
    const std::size_t count = Get<std::uint32_t>(field);
    if (count > (data_.size() - at_) / min_item_bytes) {
      Fail(std::string(field) + " says " + std::to_string(count) + " items but " +
           std::to_string(data_.size() - at_) + " bytes are left");
    }
    return count;
  }
  void GetDoubles(double* out, int n, const char* field) {
    for (int i = 0; i < n; ++i) out[i] = Get<double>(field);
  }
  Header GetHeader() {
    Get<std::uint32_t>("header.seq");
    const std::uint32_t sec = Get<std::uint32_t>("header.stamp.sec");
    const std::uint32_t nsec = Get<std::uint32_t>("header.stamp.nsec");
    Header h;
    h.stamp_s = static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec);  // as ros::Time::toSec
    h.frame_id = GetString("header.frame_id");
    return h;
  }
  void ExpectEnd() const {
    if (at_ != data_.size())
      Fail(std::to_string(data_.size() - at_) + " bytes left over after the whole message");
  }

 private:
  void Need(std::size_t bytes, const char* field) const {
    if (data_.size() - at_ < bytes) {
      Fail(std::string(field) + " needs " + std::to_string(bytes) + " bytes, " +
           std::to_string(data_.size() - at_) + " are left");
    }
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw Error(std::string("a message does not decode as ") + type_ + " (" + what + ")");
  }
  std::string_view data_;
  const char* type_;
  std::size_t at_ = 0;
};

// geometry_msgs/Pose (position, quaternion x y z w) as T_parent_child.
Eigen::Isometry3d GetPose(SerializedReader& r, const std::string& what) {
  double v[7];
  r.GetDoubles(v, 7, "pose");
  return PoseFromRosValues(v[0], v[1], v[2], v[3], v[4], v[5], v[6], what);
}

TransformMessage GetTransformStamped(SerializedReader& r) {
  TransformMessage t;
  t.header = r.GetHeader();
  t.child_frame_id = r.GetString("child_frame_id");
  t.transform = GetPose(r, "transform " + t.header.frame_id + " -> " + t.child_frame_id);
  return t;
}

}  // namespace

ImageMessage DecodeImage(std::string_view data) {
  SerializedReader r(data, kImageType.datatype);
  ImageMessage m;
  m.header = r.GetHeader();
  m.height = r.Get<std::uint32_t>("height");
  m.width = r.Get<std::uint32_t>("width");
  m.encoding = r.GetString("encoding");
  m.big_endian = r.Get<std::uint8_t>("is_bigendian") != 0;
  m.step = r.Get<std::uint32_t>("step");
  const std::string_view bytes = r.GetBytes(r.Get<std::uint32_t>("data"), "data");
  m.data.assign(bytes.begin(), bytes.end());
  r.ExpectEnd();
  return m;
}

OdometryMessage DecodeOdometry(std::string_view data) {
  SerializedReader r(data, kOdometryType.datatype);
  OdometryMessage m;
  m.header = r.GetHeader();
  m.child_frame_id = r.GetString("child_frame_id");
  m.pose = GetPose(r, "nav_msgs/Odometry pose");
  double covariance[36];
  r.GetDoubles(covariance, 36, "pose.covariance");
  m.pose_covariance = CovarianceFromRosValues(covariance, "nav_msgs/Odometry pose");
  double twist[6 + 36];  // twist and its covariance: not used by uwscan, but part of the message
  r.GetDoubles(twist, 6 + 36, "twist");
  r.ExpectEnd();
  return m;
}

std::vector<TransformMessage> DecodeTransforms(std::string_view data) {
  SerializedReader r(data, kTransformsType.datatype);
  // The smallest geometry_msgs/TransformStamped: seq, stamp, two empty strings, 7 doubles.
  constexpr std::size_t kMinTransformBytes = 4 + 8 + 4 + 4 + 7 * 8;
  const std::size_t count = r.GetCount("transforms", kMinTransformBytes);
  std::vector<TransformMessage> out;
  out.reserve(count);
  for (std::size_t i = 0; i < count; ++i) out.push_back(GetTransformStamped(r));
  r.ExpectEnd();
  return out;
}

StringMessage DecodeString(std::string_view data) {
  SerializedReader r(data, kStringType.datatype);
  StringMessage m{r.GetString("data")};
  r.ExpectEnd();
  return m;
}

}  // namespace uwscan::ros
