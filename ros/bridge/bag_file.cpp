// BagWriter (bag_file.hpp) through Debian's rosbag, which writes what it is given safely; bags
// are read by uwscan's own reader (bag_reader.cpp, bag_container.hpp says why).
#include "ros/bridge/bag_file.hpp"

#include <rosbag/bag.h>

#include <filesystem>

#include "ros/bridge/message_conversions.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

// rosbag needs ROS time initialised, and nothing else of ROS.
void InitRosTime() {
  if (!::ros::Time::isValid()) ::ros::Time::init();
}

}  // namespace

struct BagWriter::Impl {
  std::string path;
  rosbag::Bag bag;
  bool open = false;

  template <typename RosMessage>
  void Write(const std::string& topic, double record_time_s, const RosMessage& message,
             bool latched = false) {
    if (!open) throw Error(path + ": the bag is closed");
    try {
      // rosbag refuses times below one nanosecond.
      const ::ros::Time t =
          ToRosTime(record_time_s) < ::ros::TIME_MIN ? ::ros::TIME_MIN : ToRosTime(record_time_s);
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
void BagWriter::Write(const std::string& topic, const std::vector<MarkerMessage>& markers,
                      double record_time_s) {
  impl_->Write(topic, record_time_s, ToRos(markers));
}
void BagWriter::Write(const std::string& topic, const StringMessage& m, double record_time_s,
                      bool latched) {
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
