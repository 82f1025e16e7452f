#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ros/bridge/messages.hpp"

// ROS 1 bags read and written in uwscan's message types (messages.hpp): read by uwscan's own
// bounded reader (bag_container.hpp says why), written through Debian's rosbag library. No ROS
// master is needed. C++17, no ROS include.
namespace uwscan::ros {

struct BagTopic {
  std::string name;
  std::string datatype;  // "sensor_msgs/Image", ...
  std::int64_t messages = 0;
};

// What BagReader::Read hands over, one callback per message type; a message of a topic asked
// for whose type has no callback here is an error naming the topic and its type.
struct BagVisitor {
  std::function<void(const std::string& topic, ImageMessage&&)> image;
  std::function<void(const std::string& topic, OdometryMessage&&)> odometry;
  // tf2_msgs/TFMessage (on /tf and /tf_static).
  std::function<void(const std::string& topic, std::vector<TransformMessage>&&)> transforms;
  std::function<void(const std::string& topic, StringMessage&&)> text;
};

class BagReader {
 public:
  // Throws uwscan::Error naming the file when it is missing or not a readable bag.
  explicit BagReader(const std::string& path);
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  std::vector<BagTopic> Topics() const;
  // Every message of `topics` in the order it was recorded (record time; a topic asked for
  // that the bag lacks is skipped: check Topics() first). Throws uwscan::Error naming the file
  // and topic when a message does not decode or its fields are invalid (a NaN pose, ...), and
  // whatever a callback throws.
  void Read(const std::vector<std::string>& topics, const BagVisitor& visitor) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes a new bag (uncompressed). Each message is recorded at the time given (its header
// stamp for stamped messages). Throws uwscan::Error naming the file and topic on any failure.
class BagWriter {
 public:
  explicit BagWriter(const std::string& path);  // the file must not exist yet
  ~BagWriter();
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  void Write(const std::string& topic, const ImageMessage& message);
  void Write(const std::string& topic, const OdometryMessage& message);
  void Write(const std::string& topic, const CloudMessage& message);
  void Write(const std::string& topic, const PathMessage& message);
  void Write(const std::string& topic, const PoseMessage& message);
  void Write(const std::string& topic, const PoseArrayMessage& message);
  // A tf2_msgs/TFMessage, recorded at `record_time_s`.
  void Write(const std::string& topic, const std::vector<TransformMessage>& transforms,
             double record_time_s);
  // A visualization_msgs/MarkerArray, recorded at `record_time_s`.
  void Write(const std::string& topic, const std::vector<MarkerMessage>& markers,
             double record_time_s);
  // A std_msgs/String, recorded at `record_time_s`; `latched` marks the connection as latching
  // (rosbag play republishes it to late subscribers).
  void Write(const std::string& topic, const StringMessage& message, double record_time_s,
             bool latched);
  // Closes the file (the index is written): the bag is whole only after this.
  void Close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::ros
