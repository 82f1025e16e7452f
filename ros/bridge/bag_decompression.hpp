#pragma once

#include <cstddef>
#include <string>
#include <string_view>

// The chunks of a ROS bag as rosbag compresses them: "none", "bz2" (one bzip2 stream) or "lz4"
// (one LZ4 frame, roslz4's stream format). C++17, no ROS include.
namespace uwscan::ros {

// The largest chunk uwscan reads (rosbag's default chunks are 768 KB; a chunk holds at least one
// whole message, and a 2048x1088 mono16 image is 4.5 MB).
inline constexpr std::size_t kMaxBagChunkBytes = std::size_t{1} << 30;

// `data` decompressed, which must give exactly `size` bytes (at most kMaxBagChunkBytes). Memory
// grows with what the stream really produces, never with `size` alone, so a damaged size costs
// nothing. Throws uwscan::Error saying what is wrong (unknown compression, damaged or cut data,
// a size that does not match), without naming the file: the caller does.
std::string DecompressBagChunk(std::string_view compression, std::string_view data,
                               std::size_t size);

}  // namespace uwscan::ros
