#pragma once

#include <string>

// Bags with compressed chunks, as `rosbag record --bz2/--lz4` or `rosbag compress` make them:
// BagWriter writes uncompressed chunks only, and the bag reader's tests and fuzz seeds need the
// other two. C++17, no ROS include.
namespace uwscan::ros {

enum class BagCompression { kNone, kBz2, kLz4 };

// Writes `to` (which must not exist) with every message of `from`, its record time and its
// connection header, in chunks compressed with `compression`. `from` is read through Debian's
// rosbag, which trusts its input (bag_container.hpp): give it only a bag uwscan has just written.
// Throws uwscan::Error naming the file on any failure.
void WriteCompressedCopy(const std::string& from, const std::string& to,
                         BagCompression compression);

}  // namespace uwscan::ros
