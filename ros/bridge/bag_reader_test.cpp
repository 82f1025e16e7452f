// The bag reader on damaged bags (bag_container.hpp): every kind of damage ends in a
// uwscan::Error naming the file, or in the whole bag read as it was when the damage lies where
// the reader does not look; never in a crash, a hang or another exception.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "ros/bridge/bag_compression.hpp"
#include "ros/bridge/bag_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"

namespace uwscan::ros {
namespace {

namespace fs = std::filesystem;

class BagReaderDamage : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("uwscan_bag_reader_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    WriteDive(dir_ / "none.bag");
    WriteCompressedCopy((dir_ / "none.bag").string(), (dir_ / "lz4.bag").string(),
                        BagCompression::kLz4);
    WriteCompressedCopy((dir_ / "none.bag").string(), (dir_ / "bz2.bag").string(),
                        BagCompression::kBz2);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // Frames of 300 KB (so that the bag has several chunks of rosbag's 768 KB), odometry, /tf,
  // /tf_static and a latched description: every message type uwscan reads. No two messages share
  // a record time: WriteCompressedCopy copies in rosbag's time order, whose order of equal times
  // is its own.
  static void WriteDive(const fs::path& path) {
    BagWriter bag(path.string());
    bag.Write("/dive", StringMessage{"uwscan_format: 1"}, 99.98, true);
    TransformMessage mount;
    mount.header = {99.99, "base_link"};
    mount.child_frame_id = "camera";
    mount.transform.translation() = Eigen::Vector3d(0.3, 0.0, 0.2);
    bag.Write("/tf_static", std::vector<TransformMessage>{mount}, 99.99);
    for (int i = 0; i < 8; ++i) {
      ImageMessage image;
      image.header = {100.0 + 0.1 * i, "camera"};
      image.width = 600;
      image.height = 250;
      image.step = 1200;
      image.encoding = "mono16";
      image.data.resize(300000);
      for (std::size_t k = 0; k < image.data.size(); ++k)
        image.data[k] = static_cast<std::uint8_t>((k * 7 + i) % 251);
      bag.Write("/frames", image);
      OdometryMessage odometry;
      odometry.header = {100.05 + 0.1 * i, "odom"};
      odometry.child_frame_id = "base_link";
      odometry.pose.translation() = Eigen::Vector3d(0.1 * i, 0.0, 9.0);
      odometry.pose_covariance = Covariance6d::Identity() * (i + 1);
      bag.Write("/odometry", odometry);
      TransformMessage tf = mount;
      tf.header = {100.07 + 0.1 * i, "odom"};
      tf.child_frame_id = "base_link";
      bag.Write("/tf", std::vector<TransformMessage>{tf}, 100.07 + 0.1 * i);
    }
    bag.Close();
  }

  // Everything the reader gives back, one line per message (topic, stamp, content hash), and the
  // topics with their counts. Throws what the reader throws.
  static std::string ReadAll(const fs::path& path) {
    const BagReader reader(path.string());
    std::ostringstream out;
    std::vector<std::string> names;
    for (const BagTopic& t : reader.Topics()) {
      out << t.name << ' ' << t.datatype << ' ' << t.messages << '\n';
      names.push_back(t.name);
    }
    BagVisitor v;
    v.image = [&](const std::string& topic, ImageMessage&& m) {
      out << topic << ' ' << m.header.stamp_s << ' ' << m.encoding << ' ' << m.width << 'x'
          << m.height << ' ' << std::hash<std::string>()(std::string(m.data.begin(), m.data.end()))
          << '\n';
    };
    v.odometry = [&](const std::string& topic, OdometryMessage&& m) {
      out << topic << ' ' << m.header.stamp_s << ' ' << m.pose.translation().transpose() << ' '
          << m.pose_covariance.sum() << '\n';
    };
    v.transforms = [&](const std::string& topic, std::vector<TransformMessage>&& m) {
      for (const TransformMessage& t : m)
        out << topic << ' ' << t.child_frame_id << ' ' << t.header.stamp_s << '\n';
    };
    v.text = [&](const std::string& topic, StringMessage&& m) {
      out << topic << ' ' << m.data << '\n';
    };
    reader.Read(names, v);
    return out.str();
  }

  // Reads `bytes` as a bag: true when it was read whole, false when refused with a uwscan::Error
  // naming the file (anything else fails the test: another exception, or an error without the
  // file's name). `read` receives what ReadAll gave.
  static bool ReadsOrIsRefusedByName(const std::string& bytes, std::string* read = nullptr) {
    const fs::path path = dir_ / "damaged.bag";
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(bytes.data(), std::streamsize(bytes.size()));
    try {
      const std::string all = ReadAll(path);
      if (read != nullptr) *read = all;
      return true;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": ", 0), 0u) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      last_error_ = e.what();
      return false;
    }
  }

  static std::string Bytes(const char* name) { return ReadFileBytes(dir_ / name); }

  static fs::path dir_;
  static std::string last_error_;
};

fs::path BagReaderDamage::dir_;
std::string BagReaderDamage::last_error_;

// Where a record's parts lie in a bag's bytes (for placing damage; the reader does not use it).
struct RawRecord {
  std::size_t at = 0, header_at = 0, header_length = 0, data_at = 0, data_length = 0;
  std::size_t end() const { return data_at + data_length; }
};

std::uint32_t U32(const std::string& bytes, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

RawRecord RecordAt(const std::string& bytes, std::size_t at) {
  RawRecord r;
  r.at = at;
  r.header_at = at + 4;
  r.header_length = U32(bytes, at);
  r.data_at = r.header_at + r.header_length + 4;
  r.data_length = U32(bytes, r.data_at - 4);
  return r;
}

// Where the value of header field `name` of record `r` starts.
std::size_t FieldValue(const std::string& bytes, const RawRecord& r, const std::string& name) {
  for (std::size_t at = r.header_at; at < r.header_at + r.header_length;) {
    const std::uint32_t length = U32(bytes, at);
    if (bytes.compare(at + 4, name.size() + 1, name + "=") == 0) return at + 4 + name.size() + 1;
    at += 4 + length;
  }
  ADD_FAILURE() << "no field " << name << " in the record at byte " << r.at;
  return r.header_at;
}

std::uint8_t Op(const std::string& bytes, const RawRecord& r) {
  return static_cast<std::uint8_t>(bytes[FieldValue(bytes, r, "op")]);
}

// Every record from the first after the bag header to the end of the file, in order.
std::vector<RawRecord> Records(const std::string& bytes) {
  std::vector<RawRecord> records;
  for (std::size_t at = RecordAt(bytes, 13).end(); at < bytes.size(); at = records.back().end()) {
    records.push_back(RecordAt(bytes, at));
  }
  return records;
}

RawRecord First(const std::string& bytes, std::uint8_t op) {
  for (const RawRecord& r : Records(bytes)) {
    if (Op(bytes, r) == op) return r;
  }
  ADD_FAILURE() << "no record of op " << int(op);
  return {};
}

TEST_F(BagReaderDamage, CompressedChunksReadAsTheUncompressedBag) {
  const std::string none = ReadAll(dir_ / "none.bag");
  EXPECT_NE(none.find("/frames sensor_msgs/Image 8"), std::string::npos) << none;
  EXPECT_EQ(ReadAll(dir_ / "lz4.bag"), none);
  EXPECT_EQ(ReadAll(dir_ / "bz2.bag"), none);
  int chunks = 0;
  const std::string bytes = Bytes("none.bag");
  for (const RawRecord& r : Records(bytes)) chunks += Op(bytes, r) == 0x05;
  EXPECT_GE(chunks, 3) << "the bag should span several chunks";
}

TEST_F(BagReaderDamage, ABagWithoutMessagesHasNoTopics) {
  const fs::path path = dir_ / "empty.bag";
  BagWriter(path.string()).Close();
  const BagReader reader(path.string());
  EXPECT_TRUE(reader.Topics().empty());
  int messages = 0;
  BagVisitor v;
  v.text = [&](const std::string&, StringMessage&&) { ++messages; };
  reader.Read({"/dive"}, v);
  EXPECT_EQ(messages, 0);
}

TEST_F(BagReaderDamage, EveryCutIsRefusedByName) {
  for (const char* name : {"none.bag", "lz4.bag", "bz2.bag"}) {
    const std::string bytes = Bytes(name);
    std::vector<std::size_t> cuts = {0, 1, 12, 13, 16, 17, 100, 4108, 4109, 4200, bytes.size() - 1};
    for (std::size_t k = 1; k < 60; ++k) cuts.push_back(bytes.size() * k / 60);
    for (std::size_t cut : cuts) {
      EXPECT_FALSE(ReadsOrIsRefusedByName(bytes.substr(0, cut)))
          << name << " cut at " << cut << " was read";
    }
  }
}

TEST_F(BagReaderDamage, DamageWhereTheReaderDoesNotLookLeavesTheBagWhole) {
  const std::string bytes = Bytes("none.bag");
  const std::string whole = ReadAll(dir_ / "none.bag");
  // The bag header record's padding (spaces up to 4 KB).
  const RawRecord header = RecordAt(bytes, 13);
  std::string damaged = bytes;
  for (std::size_t at = header.data_at; at < header.end(); at += 7)
    damaged[at] = static_cast<char>(at);
  std::string read;
  ASSERT_TRUE(ReadsOrIsRefusedByName(damaged, &read)) << last_error_;
  EXPECT_EQ(read, whole);
  // rosbag's per-chunk message offsets (index data records): this reader finds the messages in
  // the chunk itself, and checks their count against the chunk info.
  damaged = bytes;
  for (const RawRecord& r : Records(bytes)) {
    if (Op(bytes, r) == 0x04) std::memset(damaged.data() + r.data_at, 0xFF, r.data_length);
  }
  ASSERT_TRUE(ReadsOrIsRefusedByName(damaged, &read)) << last_error_;
  EXPECT_EQ(read, whole);
}

TEST_F(BagReaderDamage, DamagedStructureIsRefusedNamingWhatIsWrong) {
  const std::string bytes = Bytes("none.bag");
  const std::size_t index_field = FieldValue(bytes, RecordAt(bytes, 13), "index_pos");
  std::uint64_t index_position = 0;
  std::memcpy(&index_position, bytes.data() + index_field, 8);
  const auto refused = [&](std::string damaged, const std::string& expected,
                           const std::string& what) {
    EXPECT_FALSE(ReadsOrIsRefusedByName(damaged)) << what << " was read";
    EXPECT_NE(last_error_.find(expected), std::string::npos) << what << ": " << last_error_;
  };
  std::string d = bytes;
  d.replace(0, 12, "#ROSBAG V1.2");
  refused(d, "not a ROS bag of version 2.0", "version 1.2");
  d = bytes;
  std::memset(d.data() + index_field, 0, 8);
  refused(d, "never closed", "an index position of 0");
  d = bytes;
  std::memset(d.data() + index_field + 4, 0x7F, 4);
  refused(d, "outside the file", "an index position past the end");
  const RawRecord chunk_info = First(bytes, 0x06);
  d = bytes;
  d[chunk_info.data_at + 4] =
      static_cast<char>(d[chunk_info.data_at + 4] + 1);  // first connection's count
  refused(d, "its index says", "a chunk info's message count one higher");
  const RawRecord chunk = First(bytes, 0x05);
  d = bytes;
  std::memset(d.data() + chunk.at, 0xFF, 4);
  refused(d, "the file ends at byte", "a chunk's header length of 4 GB");
  d = bytes;
  std::memset(d.data() + FieldValue(bytes, chunk, "size"), 0xFF, 4);
  refused(d, "more than uwscan reads", "a chunk size of 4 GB");
  d = bytes;
  const RawRecord message =
      RecordAt(bytes, RecordAt(bytes, chunk.data_at).end());  // after the first connection
  ASSERT_EQ(Op(bytes, message), 0x02);
  d[FieldValue(bytes, message, "time") + 3] = 0x7F;  // seconds moved decades ahead
  refused(d, "outside its index's", "a message's time outside its chunk's");
  d = bytes;
  const std::size_t md5 = bytes.find("md5sum=", index_position);
  ASSERT_NE(md5, std::string::npos);
  d[md5 + 7] = d[md5 + 7] == 'a' ? 'b' : 'a';
  refused(d, "of another definition", "a connection's md5sum");
}

TEST_F(BagReaderDamage, DamagedCompressedDataIsRefusedByItsChecksum) {
  for (const char* name : {"lz4.bag", "bz2.bag"}) {
    const std::string bytes = Bytes(name);
    const RawRecord chunk = First(bytes, 0x05);
    for (std::size_t at : {chunk.data_at + chunk.data_length / 3,
                           chunk.data_at + chunk.data_length / 2, chunk.end() - 2}) {
      std::string d = bytes;
      d[at] = static_cast<char>(d[at] ^ 0x10);
      EXPECT_FALSE(ReadsOrIsRefusedByName(d)) << name << ": byte " << at << " flipped was read";
    }
  }
}

TEST_F(BagReaderDamage, RandomDamageEndsReadOrRefusedByName) {
  std::mt19937_64 rng(48);
  for (const char* name : {"none.bag", "lz4.bag", "bz2.bag"}) {
    const std::string bytes = Bytes(name);
    for (int trial = 0; trial < 60; ++trial) {
      std::string d = bytes;
      const int kind = trial % 3;
      if (kind == 0) {  // bytes changed anywhere
        for (int k = 0; k < 1 + trial % 8; ++k) d[rng() % d.size()] = static_cast<char>(rng());
      } else if (kind == 1) {  // bytes changed in the index at the end
        const std::size_t from = d.size() - d.size() / 50;
        for (int k = 0; k < 1 + trial % 4; ++k)
          d[from + rng() % (d.size() - from)] = static_cast<char>(rng());
      } else {  // a block of zeros
        const std::size_t length = std::size_t{16} << (rng() % 10);
        std::memset(d.data() + rng() % (d.size() - length), 0, length);
      }
      ReadsOrIsRefusedByName(d);  // checks how it ends; a crash ends the test
    }
  }
}

}  // namespace
}  // namespace uwscan::ros
