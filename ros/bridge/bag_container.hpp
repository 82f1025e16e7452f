#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

// ROS 1 bags (format 2.0, wiki.ros.org/Bags/Format/2.0) read by uwscan's own bounded code.
//
// Why not Debian's rosbag 1.15, which wrote them: fed damaged bags
// (bench/robustness/damage_bags.py; bench/robustness/RESULTS.md) it segfaulted, read past its
// buffers (valgrind: invalid reads in Bag::readHeaderFromBuffer, so one file failed differently
// from run to run), printed to stderr, trusted the lengths it read, and its instantiate() gives
// a null message for a damaged md5 sum. Reading through rosbag in a child process would have
// turned its crashes into errors, but not the out-of-bounds reads that do not crash (they can
// hand over garbage as data), and a system library cannot be fuzzed with sanitizers. The format
// is small (records of length-prefixed name=value fields; chunks of records, uncompressed, bz2 or
// lz4), so uwscan reads it itself: every length is checked against what is left of the file or
// the chunk before anything is read or allocated, memory stays below the largest record (a chunk
// is 1 GiB at most), and the chunk index is checked against the chunks' contents. C++17, no ROS
// include: the fuzz build compiles it without ROS.
//
// Not read: bags of versions other than 2.0, bags that were never closed (no index: `rosbag
// reindex` them), encrypted bags.
namespace uwscan::ros {

// A ROS time as a bag stores it.
struct BagTime {
  std::uint32_t sec = 0;
  std::uint32_t nsec = 0;  // < 1e9
  double seconds() const { return static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec); }
  bool operator<(const BagTime& o) const { return sec != o.sec ? sec < o.sec : nsec < o.nsec; }
  bool operator>(const BagTime& o) const { return o < *this; }
};

// A connection: one publisher's topic and message type, as the bag's index lists it.
struct BagConnection {
  std::uint32_t id = 0;
  std::string topic;
  std::string datatype;  // "sensor_msgs/Image"
  std::string md5sum;    // of the message definition
};

// What the index says of one chunk.
struct BagChunkInfo {
  std::uint64_t position = 0;                       // byte offset of the chunk record in the file
  BagTime start, end;                               // record times of its first and last message
  std::map<std::uint32_t, std::uint32_t> messages;  // connection id -> its messages in the chunk
};

class BagContainer {
 public:
  // Reads the version line, the bag header and the index (connections and chunk infos). Throws
  // uwscan::Error naming the file when it cannot be read, is not a ROS bag 2.0, or its header
  // or index is damaged or cut short.
  explicit BagContainer(std::string path);

  const std::vector<BagConnection>& connections() const { return connections_; }
  const std::vector<BagChunkInfo>& chunks() const { return chunks_; }  // by position in the file

  using Visit =
      std::function<void(const BagConnection& connection, BagTime time, std::string_view data)>;
  // Calls `visit` with the serialized bytes of every message of the connections `wanted`, in
  // record-time order (equal times in file order), reading only the chunks that hold them.
  // Throws uwscan::Error naming the file when a chunk is damaged, cut short or disagrees with the
  // index (another message count, a time outside the chunk's range, an unknown connection), and
  // whatever `visit` throws.
  void ForEachMessage(const std::set<std::uint32_t>& wanted, const Visit& visit) const;

 private:
  struct MessageEntry;
  class File;
  void ReadIndex(File& file, std::uint64_t index_position, std::uint32_t connections,
                 std::uint32_t chunks);
  std::uint64_t ReadConnection(File& file,
                               std::uint64_t at);  // returns where the next record starts
  std::uint64_t ReadChunkInfo(File& file, std::uint64_t at);
  std::size_t CheckMessage(const BagChunkInfo& info, std::uint32_t connection, BagTime time) const;
  std::string LoadChunk(File& file, std::size_t chunk) const;
  void ScanChunk(std::string_view buffer, std::size_t chunk, const std::set<std::uint32_t>& wanted,
                 std::vector<MessageEntry>& entries) const;
  std::vector<MessageEntry> IndexMessages(File& file, const std::set<std::uint32_t>& wanted) const;

  std::string path_;
  std::uint64_t records_begin_ = 0;  // after the bag header record
  std::uint64_t index_position_ = 0;
  std::vector<BagConnection> connections_;
  std::map<std::uint32_t, std::size_t> connection_slot_;  // id -> index in connections_
  std::vector<BagChunkInfo> chunks_;
};

}  // namespace uwscan::ros
