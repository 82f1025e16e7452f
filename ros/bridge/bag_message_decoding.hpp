#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "ros/bridge/messages.hpp"

// The messages uwscan reads from bags, decoded from ROS 1's serialization (little-endian
// fixed-size fields; strings and arrays as a uint32 length then the items) by uwscan's own
// bounded code rather than ROS's generated deserializers, which size a vector from the length
// they read before checking that the bytes are there (a damaged length of 4e9 allocates 4 GB)
// and ignore bytes left over. Every length is checked against the bytes that remain, and a
// message must use its bytes exactly. C++17, no ROS include: the fuzz build compiles it without
// ROS.
namespace uwscan::ros {

// A message type uwscan reads and the md5 sum of its definition, as a bag's connection records
// it (Debian 12's message packages; a bag of another definition of the type is refused).
struct BagMessageType {
  const char* datatype;
  const char* md5sum;
};
inline constexpr BagMessageType kImageType{"sensor_msgs/Image", "060021388200f6f0f447d0fcd9c64743"};
inline constexpr BagMessageType kOdometryType{"nav_msgs/Odometry",
                                              "cd5e73d190d741a2f92e81eda573aca7"};
inline constexpr BagMessageType kTransformsType{"tf2_msgs/TFMessage",
                                                "94810edda583a504dfda3829e70d7eec"};
inline constexpr BagMessageType kStringType{"std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1"};

// Each throws uwscan::Error saying what is wrong (a length past the end, bytes left over, a pose
// that is not finite ...) without naming the file: the caller adds the file and the topic.
ImageMessage DecodeImage(std::string_view data);
OdometryMessage DecodeOdometry(std::string_view data);
std::vector<TransformMessage> DecodeTransforms(std::string_view data);
StringMessage DecodeString(std::string_view data);

}  // namespace uwscan::ros
