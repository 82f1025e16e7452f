#include "ros/bridge/bag_file.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <filesystem>
#include <map>

#include "ros/bridge/message_conversions.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

// rosbag needs ROS time initialised, and nothing else of ROS.
void InitRosTime() {
  if (!::ros::Time::isValid()) ::ros::Time::init();
}

}  // namespace

struct BagReader::Impl {
  std::string path;
  mutable rosbag::Bag bag;
};

BagReader::BagReader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  InitRosTime();
  impl_->path = path;
  if (!std::filesystem::is_regular_file(path)) throw Error(path + ": no such bag file");
  try {
    impl_->bag.open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw Error(path + ": not a readable ROS bag (" + e.what() + ")");
  }
}

BagReader::~BagReader() = default;

std::vector<BagTopic> BagReader::Topics() const {
  std::map<std::string, BagTopic> topics;
  try {
    rosbag::View view(impl_->bag);
    for (const rosbag::ConnectionInfo* c : view.getConnections()) {
      BagTopic& t = topics[c->topic];
      t.name = c->topic;
      t.datatype = c->datatype;
    }
    for (auto& [name, topic] : topics) {
      rosbag::View one(impl_->bag, rosbag::TopicQuery(name));
      topic.messages = static_cast<std::int64_t>(one.size());
    }
  } catch (const std::exception& e) {
    throw Error(impl_->path + ": the bag's index does not read (" + e.what() + ")");
  }
  std::vector<BagTopic> out;
  for (auto& [name, topic] : topics) out.push_back(topic);
  return out;
}

void BagReader::Read(const std::vector<std::string>& topics, const BagVisitor& visitor) const {
  const auto missing_callback = [&](const std::string& topic, const std::string& type) {
    return Error(impl_->path + ": topic " + topic + " is " + type + ", which uwscan does not read there");
  };
  rosbag::View view(impl_->bag, rosbag::TopicQuery(topics));
  for (const rosbag::MessageInstance& m : view) {
    const std::string& topic = m.getTopic();
    const std::string& type = m.getDataType();
    try {
      if (type == "sensor_msgs/Image") {
        if (!visitor.image) throw missing_callback(topic, type);
        visitor.image(topic, FromRos(*m.instantiate<sensor_msgs::Image>()));
      } else if (type == "nav_msgs/Odometry") {
        if (!visitor.odometry) throw missing_callback(topic, type);
        visitor.odometry(topic, FromRos(*m.instantiate<nav_msgs::Odometry>()));
      } else if (type == "tf2_msgs/TFMessage") {
        if (!visitor.transforms) throw missing_callback(topic, type);
        visitor.transforms(topic, FromRos(*m.instantiate<tf2_msgs::TFMessage>()));
      } else if (type == "std_msgs/String") {
        if (!visitor.text) throw missing_callback(topic, type);
        visitor.text(topic, FromRos(*m.instantiate<std_msgs::String>()));
      } else {
        throw missing_callback(topic, type);
      }
    } catch (const Error& e) {
      const std::string what = e.what();
      if (what.rfind(impl_->path, 0) == 0) throw;
      throw Error(impl_->path + ": topic " + topic + " at " + std::to_string(m.getTime().toSec()) + " s: " + what);
    } catch (const std::exception& e) {
      throw Error(impl_->path + ": topic " + topic + ": a message does not decode as " + type + " (" + e.what() + ")");
    }
  }
}

struct BagWriter::Impl {
  std::string path;
  rosbag::Bag bag;
  bool open = false;

  template <typename RosMessage>
  void Write(const std::string& topic, double record_time_s, const RosMessage& message, bool latched = false) {
    if (!open) throw Error(path + ": the bag is closed");
    try {
      // rosbag refuses times below one nanosecond.
      const ::ros::Time t = ToRosTime(record_time_s) < ::ros::TIME_MIN ? ::ros::TIME_MIN : ToRosTime(record_time_s);
      if (latched) {
        // A connection header given to write() replaces rosbag's own: it names the type too.
        auto header = boost::make_shared<::ros::M_string>();
        (*header)["type"] = ::ros::message_traits::datatype(message);
        (*header)["md5sum"] = ::ros::message_traits::md5sum(message);
        (*header)["message_definition"] = ::ros::message_traits::definition(message);
        (*header)["latching"] = "1";
        (*header)["callerid"] = "/uwscan";
        bag.write(topic, t, message, header);
      } else {
        bag.write(topic, t, message);
      }
    } catch (const Error& e) {
      throw Error(path + ": topic " + topic + ": " + e.what());
    } catch (const std::exception& e) {
      throw Error(path + ": topic " + topic + ": cannot write (" + e.what() + ")");
    }
  }
};

BagWriter::BagWriter(const std::string& path) : impl_(std::make_unique<Impl>()) {
  InitRosTime();
  impl_->path = path;
  if (std::filesystem::exists(path)) throw Error(path + ": exists (a bag is never overwritten)");
  try {
    impl_->bag.open(path, rosbag::bagmode::Write);
  } catch (const std::exception& e) {
    throw Error(path + ": cannot create the bag (" + e.what() + ")");
  }
  impl_->open = true;
}

BagWriter::~BagWriter() {
  try {
    Close();
  } catch (...) {
  }
}

void BagWriter::Write(const std::string& topic, const ImageMessage& m) {
  impl_->Write(topic, m.header.stamp_s, ToRos(m));
}
void BagWriter::Write(const std::string& topic, const OdometryMessage& m) {
  impl_->Write(topic, m.header.stamp_s, ToRos(m));
}
void BagWriter::Write(const std::string& topic, const CloudMessage& m) {
  impl_->Write(topic, m.header.stamp_s, ToRos(m));
}
void BagWriter::Write(const std::string& topic, const PathMessage& m) {
  impl_->Write(topic, m.header.stamp_s, ToRos(m));
}
void BagWriter::Write(const std::string& topic, const PoseMessage& m) {
  impl_->Write(topic, m.header.stamp_s, ToRos(m));
}
void BagWriter::Write(const std::string& topic, const PoseArrayMessage& m) {
  impl_->Write(topic, m.header.stamp_s, ToRos(m));
}
void BagWriter::Write(const std::string& topic, const std::vector<TransformMessage>& transforms,
                      double record_time_s) {
  impl_->Write(topic, record_time_s, ToRos(transforms), topic == "/tf_static");
}
void BagWriter::Write(const std::string& topic, const std::vector<MarkerMessage>& markers, double record_time_s) {
  impl_->Write(topic, record_time_s, ToRos(markers));
}
void BagWriter::Write(const std::string& topic, const StringMessage& m, double record_time_s, bool latched) {
  impl_->Write(topic, record_time_s, ToRos(m), latched);
}

void BagWriter::Close() {
  if (!impl_->open) return;
  impl_->open = false;
  try {
    impl_->bag.close();
  } catch (const std::exception& e) {
    throw Error(impl_->path + ": cannot close the bag (" + e.what() + ")");
  }
}

}  // namespace uwscan::ros
