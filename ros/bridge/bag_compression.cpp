#include "ros/bridge/bag_compression.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <filesystem>

#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

rosbag::compression::CompressionType ToRosbag(BagCompression c) {
  switch (c) {
    case BagCompression::kBz2:
      return rosbag::compression::BZ2;
    case BagCompression::kLz4:
      return rosbag::compression::LZ4;
    case BagCompression::kNone:
      break;
  }
  return rosbag::compression::Uncompressed;
}

}  // namespace

void WriteCompressedCopy(const std::string& from, const std::string& to,
                         BagCompression compression) {
  if (!::ros::Time::isValid()) ::ros::Time::init();  // rosbag needs ROS time, nothing else of ROS
  if (std::filesystem::exists(to)) throw Error(to + ": exists (a bag is never overwritten)");
  try {
    rosbag::Bag in(from, rosbag::bagmode::Read);
    rosbag::Bag out(to, rosbag::bagmode::Write);
    out.setCompression(ToRosbag(compression));
    for (const rosbag::MessageInstance& m : rosbag::View(in)) {
      out.write(m.getTopic(), m.getTime(), m, m.getConnectionHeader());
    }
    out.close();
  } catch (const std::exception& e) {
    std::filesystem::remove(to);
    throw Error(to + ": cannot write a compressed copy of " + from + " (" + e.what() + ")");
  }
}

}  // namespace uwscan::ros
