// BagReader (bag_file.hpp) on uwscan's own bounded bag reader (bag_container.hpp says why not
// rosbag's) and message decoding (bag_message_decoding.hpp). No ROS include: the fuzz build
// compiles this file without ROS.
#include <filesystem>
#include <map>
#include <set>
#include <string_view>

#include "ros/bridge/bag_container.hpp"
#include "ros/bridge/bag_file.hpp"
#include "ros/bridge/bag_message_decoding.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

Error NotRead(const std::string& path, const BagConnection& c) {
  return Error(path + ": topic " + c.topic + " is " + c.datatype +
               ", which uwscan does not read there");
}

// Throws uwscan::Error naming the file when the visitor has no callback for the connection's
// type or the bag's definition of the type is another than uwscan decodes.
void CheckType(const std::string& path, const BagConnection& c, const BagMessageType& type,
               bool has_callback) {
  if (!has_callback) throw NotRead(path, c);
  if (c.md5sum != type.md5sum) {
    throw Error(path + ": topic " + c.topic + " is " + c.datatype +
                " of another definition (md5sum " + c.md5sum + ", uwscan reads " + type.md5sum +
                ")");
  }
}

// Hands one message to its callback. Throws as CheckType; without naming the file when the
// message's bytes do not decode or its values are invalid; and what the callback throws.
void Dispatch(const std::string& path, const BagConnection& c, std::string_view data,
              const BagVisitor& visitor) {
  if (c.datatype == kImageType.datatype) {
    CheckType(path, c, kImageType, bool(visitor.image));
    visitor.image(c.topic, DecodeImage(data));
  } else if (c.datatype == kOdometryType.datatype) {
    CheckType(path, c, kOdometryType, bool(visitor.odometry));
    visitor.odometry(c.topic, DecodeOdometry(data));
  } else if (c.datatype == kTransformsType.datatype) {
    CheckType(path, c, kTransformsType, bool(visitor.transforms));
    visitor.transforms(c.topic, DecodeTransforms(data));
  } else if (c.datatype == kStringType.datatype) {
    CheckType(path, c, kStringType, bool(visitor.text));
    visitor.text(c.topic, DecodeString(data));
  } else {
    throw NotRead(path, c);
  }
}

}  // namespace

struct BagReader::Impl {
  std::string path;
  BagContainer bag;
};

BagReader::BagReader(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw Error(path + ": no such bag file");
  impl_ = std::make_unique<Impl>(Impl{path, BagContainer(path)});
}

BagReader::~BagReader() = default;

std::vector<BagTopic> BagReader::Topics() const {
  std::map<std::string, BagTopic> topics;
  for (const BagConnection& c : impl_->bag.connections()) {
    BagTopic& t = topics[c.topic];
    t.name = c.topic;
    if (t.datatype.empty()) t.datatype = c.datatype;
    for (const BagChunkInfo& chunk : impl_->bag.chunks()) {
      const auto it = chunk.messages.find(c.id);
      if (it != chunk.messages.end()) t.messages += it->second;
    }
  }
  std::vector<BagTopic> out;
  for (auto& [name, topic] : topics) out.push_back(topic);
  return out;
}

void BagReader::Read(const std::vector<std::string>& topics, const BagVisitor& visitor) const {
  const std::set<std::string> asked(topics.begin(), topics.end());
  std::set<std::uint32_t> wanted;
  for (const BagConnection& c : impl_->bag.connections()) {
    if (asked.count(c.topic) != 0) wanted.insert(c.id);
  }
  const std::string& path = impl_->path;
  impl_->bag.ForEachMessage(wanted,
                            [&](const BagConnection& c, BagTime time, std::string_view data) {
                              try {
                                Dispatch(path, c, data, visitor);
                              } catch (const Error& e) {
                                const std::string what = e.what();
                                if (what.rfind(path, 0) == 0)
                                  throw;  // names the file already (a callback's own error, ...)
                                throw Error(path + ": topic " + c.topic + " at " +
                                            std::to_string(time.seconds()) + " s: " + what);
                              }
                            });
}

}  // namespace uwscan::ros
