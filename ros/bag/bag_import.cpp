#include "ros/bag/bag_import.hpp"

#include <optional>

#include "ros/bridge/bag_file.hpp"
#include "ros/conversions/dive_description.hpp"
#include "ros/conversions/frame_image.hpp"
#include "ros/conversions/static_transforms.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

std::string TopicList(const std::vector<BagTopic>& topics) {
  std::string list;
  for (const BagTopic& t : topics)
    list += (list.empty() ? "" : ", ") + t.name + " (" + t.datatype + ")";
  return list.empty() ? "none" : list;
}

// Throws unless the bag has `name` with messages of `datatype`.
void RequireTopic(const std::vector<BagTopic>& topics, const std::string& name,
                  const std::string& datatype, const std::string& what,
                  const std::filesystem::path& bag) {
  for (const BagTopic& t : topics) {
    if (t.name != name) continue;
    if (t.datatype != datatype) {
      throw Error(bag.string() + ": topic " + name + " is " + t.datatype + ", expected " +
                  datatype + " (" + what + ")");
    }
    if (t.messages > 0) return;
  }
  throw Error(bag.string() + ": no " + what + " on topic " + name + " (" + datatype +
              "); the bag's topics: " + TopicList(topics));
}

bool HasTopic(const std::vector<BagTopic>& topics, const std::string& name) {
  for (const BagTopic& t : topics) {
    if (t.name == name && t.messages > 0) return true;
  }
  return false;
}

// Stamps of one topic, checked to never go back.
class StampOrder {
 public:
  void Check(const std::string& topic, double stamp_s, const std::filesystem::path& bag) {
    if (last_s_ && stamp_s < *last_s_) {
      throw Error(bag.string() + ": topic " + topic + ": stamp " + std::to_string(stamp_s) +
                  " s goes back from " + std::to_string(*last_s_) + " s (message " +
                  std::to_string(count_) + ")");
    }
    last_s_ = stamp_s;
    ++count_;
  }

 private:
  std::optional<double> last_s_;
  std::int64_t count_ = 0;
};

struct Description {
  mapping::DiveLogHeader header;
  double time_origin_s = 0.0;
  bool described = false;
  StaticTransforms statics;
};

Description ReadDescription(const BagReader& reader, const std::vector<BagTopic>& topics,
                            const std::filesystem::path& bag, const BagImportOptions& o) {
  Description d;
  BagVisitor visitor;
  visitor.text = [&](const std::string& topic, StringMessage&& m) {
    if (d.described) return;
    const DiveDescription description =
        ParseDiveDescription(m.data, bag.string() + " topic " + topic);
    d.header = description.header;
    d.time_origin_s = description.time_origin_s;
    d.described = true;
  };
  visitor.transforms = [&](const std::string&, std::vector<TransformMessage>&& transforms) {
    for (const TransformMessage& t : transforms) d.statics.Add(t);
  };
  std::vector<std::string> wanted;
  if (HasTopic(topics, o.topics.dive)) wanted.push_back(o.topics.dive);
  if (HasTopic(topics, o.topics.tf_static)) wanted.push_back(o.topics.tf_static);
  if (!wanted.empty()) reader.Read(wanted, visitor);
  if (!d.described) {
    if (!o.header) {
      throw Error(bag.string() + ": no dive description on " + o.topics.dive +
                  " (a bag uwscan did not write): give the scanner (--scanner CALIB.yaml)");
    }
    d.header = *o.header;
  }
  return d;
}

const std::string& NavigationTopic(const BagImportOptions& o) {
  return o.navigation.source == NavigationSource::kTf ? o.topics.tf : o.topics.odometry;
}

// The frames and the navigation, in the order they were recorded.
void ReadDive(const BagReader& reader, const std::filesystem::path& bag, const BagImportOptions& o,
              const Description& d, mapping::DiveLogWriter& writer, BagImportSummary& summary,
              std::string& camera_frame, std::string& vehicle_frame) {
  FrameImageDecoder decoder(d.header.scanner.camera().camera, o.detector, o.keep_images);
  StampOrder frame_order, navigation_order;
  BagVisitor visitor;
  visitor.image = [&](const std::string& topic, ImageMessage&& m) {
    frame_order.Check(topic, m.header.stamp_s, bag);
    if (camera_frame.empty()) camera_frame = m.header.frame_id;
    std::optional<mapping::FrameRecord> frame =
        decoder.Decode(m, m.header.stamp_s - d.time_origin_s, bag.string() + ": topic " + topic);
    if (!frame) {
      ++summary.undecodable;
      return;
    }
    writer.AppendFrame(*frame);
    ++summary.frames;
  };
  const auto navigation = [&](const std::string& topic, const OdometryMessage& m) {
    navigation_order.Check(topic, m.header.stamp_s, bag);
    if (vehicle_frame.empty()) vehicle_frame = m.child_frame_id;
    writer.AppendNavigation(
        {m.header.stamp_s - d.time_origin_s, VehiclePoseInUwscanAxes(m.pose, o.navigation.axes)});
    ++summary.navigation;
  };
  if (o.navigation.source == NavigationSource::kOdometry) {
    visitor.odometry = navigation;
  } else {
    visitor.transforms = [&](const std::string& topic, std::vector<TransformMessage>&& ts) {
      if (const std::optional<OdometryMessage> m = NavigationFromTransforms(ts, o.frames))
        navigation(topic, *m);
    };
  }
  reader.Read({o.topics.frames, NavigationTopic(o)}, visitor);
}

}  // namespace

BagImportSummary ImportBag(const std::filesystem::path& bag, const std::filesystem::path& log,
                           const BagImportOptions& o) {
  if (std::filesystem::exists(log))
    throw Error(log.string() + ": exists (a dive log is never overwritten)");
  const BagReader reader(bag.string());
  const std::vector<BagTopic> topics = reader.Topics();
  RequireTopic(topics, o.topics.frames, "sensor_msgs/Image", "camera frames", bag);
  if (o.navigation.source == NavigationSource::kOdometry) {
    RequireTopic(topics, o.topics.odometry, "nav_msgs/Odometry", "navigation", bag);
  } else {
    RequireTopic(topics, o.topics.tf, "tf2_msgs/TFMessage", "navigation", bag);
  }
  const Description d = ReadDescription(reader, topics, bag, o);

  BagImportSummary summary;
  summary.described = d.described;
  summary.time_origin_s = d.time_origin_s;
  mapping::DiveLogHeader header = d.header;
  header.producer = o.producer;
  mapping::WriteDiveLogAtomically(log, [&](const std::filesystem::path& partial) {
    std::string camera_frame, vehicle_frame;
    mapping::DiveLogWriter writer(partial, header);
    ReadDive(reader, bag, o, d, writer, summary, camera_frame, vehicle_frame);
    if (o.navigation.source == NavigationSource::kTf && summary.navigation == 0) {
      throw Error(bag.string() + ": no " + o.frames.odom + " -> " + o.frames.base_link +
                  " transform on " + o.topics.tf + " (the navigation)");
    }
    const std::optional<Eigen::Isometry3d> T_V_C = d.statics.Find(vehicle_frame, camera_frame);
    writer.SetVehicleMount(
        MountInUwscanAxes(T_V_C.value_or(Eigen::Isometry3d::Identity()), o.navigation.axes));
    summary.mount = T_V_C ? o.topics.tf_static + " " + vehicle_frame + " -> " + camera_frame
                          : "none on " + o.topics.tf_static + " from " + vehicle_frame + " to " +
                                camera_frame + ": the camera is taken at the vehicle's origin";
  });
  return summary;
}

}  // namespace uwscan::ros
