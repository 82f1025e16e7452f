#include "ros/bridge/bag_container.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <tuple>

#include "ros/bridge/bag_decompression.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

constexpr std::string_view kVersionLine = "#ROSBAG V2.0\n";
// Record op codes (wiki.ros.org/Bags/Format/2.0).
constexpr std::uint8_t kMessageData = 0x02, kBagHeader = 0x03, kChunk = 0x05, kChunkInfo = 0x06,
                       kConnection = 0x07;

using Fields = std::map<std::string, std::string, std::less<>>;

std::uint32_t LoadU32(std::string_view bytes, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);  // bags are little-endian, as the machines uwscan targets
  return v;
}

// A record header: <len><name>=<value> fields, each length checked against the header's end.
Fields ParseFields(std::string_view header) {
  Fields fields;
  std::size_t at = 0;
  while (at < header.size()) {
    if (header.size() - at < 4) throw Error("a header field's length is cut short");
    const std::uint32_t length = LoadU32(header, at);
    at += 4;
    if (length > header.size() - at) {
      throw Error("a header field of " + std::to_string(length) + " bytes runs past its header");
    }
    const std::string_view field = header.substr(at, length);
    at += length;
    const std::size_t equals = field.find('=');
    if (equals == std::string_view::npos) throw Error("a header field has no '='");
    fields.emplace(std::string(field.substr(0, equals)), std::string(field.substr(equals + 1)));
  }
  return fields;
}

std::string_view Field(const Fields& fields, const char* name) {
  const auto it = fields.find(name);
  if (it == fields.end()) throw Error(std::string("no field '") + name + "'");
  return it->second;
}

template <typename T>
T FixedField(const Fields& fields, const char* name) {
  const std::string_view value = Field(fields, name);
  if (value.size() != sizeof(T)) {
    throw Error(std::string("field '") + name + "' has " + std::to_string(value.size()) +
                " bytes, not " + std::to_string(sizeof(T)));
  }
  T v;
  std::memcpy(&v, value.data(), sizeof(T));
  return v;
}

BagTime TimeField(const Fields& fields, const char* name) {
  const std::uint64_t packed = FixedField<std::uint64_t>(fields, name);
  const BagTime t{static_cast<std::uint32_t>(packed), static_cast<std::uint32_t>(packed >> 32)};
  if (t.nsec >= 1000000000u)
    throw Error(std::string("field '") + name + "' has " + std::to_string(t.nsec) + " ns");
  return t;
}

void ExpectOp(const Fields& fields, std::uint8_t op, const char* record) {
  const auto found = FixedField<std::uint8_t>(fields, "op");
  if (found != op) {
    throw Error(std::string("expected a ") + record + " record (op " + std::to_string(op) +
                "), found op " + std::to_string(found));
  }
}

// A record inside a chunk's bytes.
struct MemoryRecord {
  Fields fields;
  std::string_view data;
  std::size_t end = 0;
};

MemoryRecord ParseRecordAt(std::string_view buffer, std::size_t at) {
  const auto need = [&](std::size_t bytes, const char* what) {
    if (bytes > buffer.size() - at) {
      throw Error(std::string(what) + " of the record at offset " + std::to_string(at) +
                  " runs past the chunk's " + std::to_string(buffer.size()) + " bytes");
    }
  };
  need(4, "the header length");
  const std::uint32_t header_length = LoadU32(buffer, at);
  need(std::size_t{4} + header_length + 4, "the header");
  MemoryRecord r;
  r.fields = ParseFields(buffer.substr(at + 4, header_length));
  at += 4 + header_length;
  const std::uint32_t data_length = LoadU32(buffer, at);
  at += 4;
  need(data_length, "the data");
  r.data = buffer.substr(at, data_length);
  r.end = at + data_length;
  return r;
}

std::string At(std::uint64_t position) { return " at byte " + std::to_string(position); }

}  // namespace

// The bag on disk, read only in bounded pieces.
class BagContainer::File {
 public:
  explicit File(const std::string& path) : in_(path, std::ios::binary) {
    if (!in_) throw Error(path + ": cannot be opened");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
  }
  std::uint64_t size() const { return size_; }

  // `length` bytes at `position`; throws when they run past the end of the file.
  std::string Read(std::uint64_t position, std::uint64_t length, const char* what) {
    if (position > size_ || length > size_ - position) {
      throw Error(std::string(what) + At(position) + " needs " + std::to_string(length) +
                  " bytes; the file ends at byte " + std::to_string(size_));
    }
    std::string bytes(static_cast<std::size_t>(length), '\0');
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(position));
    if (!in_.read(bytes.data(), static_cast<std::streamsize>(length))) {
      throw Error(std::string(what) + At(position) + " cannot be read");
    }
    return bytes;
  }

  // A record's header fields; its data is left where it is (data_at, data_length).
  struct Record {
    Fields fields;
    std::uint64_t data_at = 0;
    std::uint32_t data_length = 0;
    std::uint64_t end = 0;
  };
  Record ReadRecord(std::uint64_t position, const char* what) {
    Record r;
    const std::uint32_t header_length = LoadU32(Read(position, 4, what), 0);
    r.fields = ParseFields(Read(position + 4, header_length, what));
    r.data_at = position + 4 + header_length + 4;
    r.data_length = LoadU32(Read(r.data_at - 4, 4, what), 0);
    if (r.data_length > size_ - std::min(size_, r.data_at)) {
      throw Error(std::string(what) + At(position) + ": its data of " +
                  std::to_string(r.data_length) + " bytes runs past the end of the file (byte " +
                  std::to_string(size_) + ")");
    }
    r.end = r.data_at + r.data_length;
    return r;
  }
  std::string ReadData(const Record& r, const char* what) {
    return Read(r.data_at, r.data_length, what);
  }

 private:
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

struct BagContainer::MessageEntry {
  BagTime time;
  std::uint32_t chunk = 0;   // index in chunks_
  std::uint32_t offset = 0;  // of its record in the decompressed chunk
  std::uint32_t slot = 0;    // index in connections_
  bool operator<(const MessageEntry& o) const {
    return std::tie(time.sec, time.nsec, chunk, offset) <
           std::tie(o.time.sec, o.time.nsec, o.chunk, o.offset);
  }
};

namespace {

// Runs `read`, naming the file in what it throws: its messages say what is wrong, not where.
template <typename Read>
auto Damaged(const std::string& path, Read read) -> decltype(read()) {
  try {
    return read();
  } catch (const Error& e) {
    throw Error(path + ": damaged or truncated bag: " + e.what());
  }
}

void CheckVersionLine(const std::string& path, std::string line) {
  if (line == kVersionLine) return;
  for (char& c : line)
    c = c >= 0x20 && c < 0x7F ? c : '?';  // a one-line message, whatever the bytes
  throw Error(path + ": not a ROS bag of version 2.0, the one uwscan reads (it starts with '" +
              line + "', not '#ROSBAG V2.0')");
}

BagConnection ParseConnection(const Fields& header, const std::string& data) {
  BagConnection c;
  c.id = FixedField<std::uint32_t>(header, "conn");
  c.topic = std::string(Field(header, "topic"));
  const Fields description = ParseFields(data);
  c.datatype = std::string(Field(description, "type"));
  c.md5sum = std::string(Field(description, "md5sum"));
  return c;
}

BagChunkInfo ParseChunkInfo(const Fields& header, const std::string& data) {
  if (FixedField<std::uint32_t>(header, "ver") != 1)
    throw Error("a chunk info record of another version than 1");
  BagChunkInfo info;
  info.position = FixedField<std::uint64_t>(header, "chunk_pos");
  info.start = TimeField(header, "start_time");
  info.end = TimeField(header, "end_time");
  if (info.end < info.start) throw Error("a chunk info record ends before it starts");
  const std::uint32_t count = FixedField<std::uint32_t>(header, "count");
  if (data.size() != std::uint64_t{count} * 8) {
    throw Error("a chunk info record of " + std::to_string(count) + " connections has " +
                std::to_string(data.size()) + " bytes of data");
  }
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t connection = LoadU32(data, 8 * i), messages = LoadU32(data, 8 * i + 4);
    if (!info.messages.emplace(connection, messages).second) {
      throw Error("a chunk info record lists connection " + std::to_string(connection) + " twice");
    }
  }
  return info;
}

}  // namespace

BagContainer::BagContainer(std::string path) : path_(std::move(path)) {
  File file(path_);
  if (file.size() < kVersionLine.size()) {
    throw Error(path_ + ": not a ROS bag (" + std::to_string(file.size()) + " bytes)");
  }
  CheckVersionLine(path_, file.Read(0, kVersionLine.size(), "the version line"));
  Damaged(path_, [&] {
    const File::Record header = file.ReadRecord(kVersionLine.size(), "the bag header");
    ExpectOp(header.fields, kBagHeader, "bag header");
    const auto encryptor = header.fields.find("encryptor");
    if (encryptor != header.fields.end() && !encryptor->second.empty()) {
      throw Error("the bag is encrypted (" + encryptor->second + "), which uwscan does not read");
    }
    records_begin_ = header.end;
    const auto index = FixedField<std::uint64_t>(header.fields, "index_pos");
    if (index == 0)
      throw Error("the bag was never closed, so it has no index (`rosbag reindex` it)");
    if (index < records_begin_ || index > file.size()) {  // at the very end: a bag without messages
      throw Error("its index position " + std::to_string(index) + " is outside the file (" +
                  std::to_string(file.size()) + " bytes)");
    }
    ReadIndex(file, index, FixedField<std::uint32_t>(header.fields, "conn_count"),
              FixedField<std::uint32_t>(header.fields, "chunk_count"));
  });
}

void BagContainer::ReadIndex(File& file, std::uint64_t index_position, std::uint32_t connections,
                             std::uint32_t chunks) {
  index_position_ = index_position;
  std::uint64_t at = index_position;
  for (std::uint32_t i = 0; i < connections; ++i) at = ReadConnection(file, at);
  for (std::uint32_t i = 0; i < chunks; ++i) at = ReadChunkInfo(file, at);
  std::sort(chunks_.begin(), chunks_.end(),
            [](const BagChunkInfo& a, const BagChunkInfo& b) { return a.position < b.position; });
  for (std::size_t i = 1; i < chunks_.size(); ++i) {
    if (chunks_[i].position == chunks_[i - 1].position)
      throw Error("two chunks" + At(chunks_[i].position));
  }
}

std::uint64_t BagContainer::ReadConnection(File& file, std::uint64_t at) {
  const File::Record r = file.ReadRecord(at, "a connection record of the index");
  ExpectOp(r.fields, kConnection, "connection");
  const BagConnection c = ParseConnection(r.fields, file.ReadData(r, "a connection record"));
  if (!connection_slot_.emplace(c.id, connections_.size()).second) {
    throw Error("the index lists connection " + std::to_string(c.id) + " twice");
  }
  connections_.push_back(c);
  return r.end;
}

std::uint64_t BagContainer::ReadChunkInfo(File& file, std::uint64_t at) {
  const File::Record r = file.ReadRecord(at, "a chunk info record of the index");
  ExpectOp(r.fields, kChunkInfo, "chunk info");
  BagChunkInfo info = ParseChunkInfo(r.fields, file.ReadData(r, "a chunk info record"));
  if (info.position < records_begin_ || info.position >= index_position_) {
    throw Error("a chunk" + At(info.position) + " lies outside the records (bytes " +
                std::to_string(records_begin_) + " to " + std::to_string(index_position_) + ")");
  }
  for (const auto& [connection, messages] : info.messages) {
    if (connection_slot_.count(connection) == 0) {
      throw Error("the chunk" + At(info.position) + " holds connection " +
                  std::to_string(connection) + ", which the index does not list");
    }
  }
  chunks_.push_back(std::move(info));
  return r.end;
}

std::string BagContainer::LoadChunk(File& file, std::size_t chunk) const {
  const std::uint64_t position = chunks_[chunk].position;
  const File::Record r = file.ReadRecord(position, "a chunk");
  ExpectOp(r.fields, kChunk, "chunk");
  if (r.end > index_position_) throw Error("the chunk" + At(position) + " runs into the index");
  try {
    return DecompressBagChunk(Field(r.fields, "compression"), file.ReadData(r, "a chunk"),
                              FixedField<std::uint32_t>(r.fields, "size"));
  } catch (const Error& e) {
    throw Error("the chunk" + At(position) + ": " + e.what());
  }
}

// The connection slot of a message record found in chunk `info`, checked against the index: a
// connection the chunk's entry lists, a time within the chunk's.
std::size_t BagContainer::CheckMessage(const BagChunkInfo& info, std::uint32_t connection,
                                       BagTime time) const {
  const auto slot = connection_slot_.find(connection);
  if (slot == connection_slot_.end() || info.messages.count(connection) == 0) {
    throw Error("the chunk" + At(info.position) + " holds a message of connection " +
                std::to_string(connection) + ", which its index entry does not list");
  }
  if (time < info.start || time > info.end) {
    throw Error("the chunk" + At(info.position) + " holds a message at " +
                std::to_string(time.seconds()) + " s, outside its index's " +
                std::to_string(info.start.seconds()) + " to " + std::to_string(info.end.seconds()) +
                " s");
  }
  return slot->second;
}

// Lists the messages of `wanted` in one chunk, each checked against the index, and checks that
// the chunk holds as many messages per connection as the index says.
void BagContainer::ScanChunk(std::string_view buffer, std::size_t chunk,
                             const std::set<std::uint32_t>& wanted,
                             std::vector<MessageEntry>& entries) const {
  const BagChunkInfo& info = chunks_[chunk];
  std::map<std::uint32_t, std::uint32_t> found;
  for (std::size_t at = 0; at < buffer.size();) {
    const MemoryRecord r = ParseRecordAt(buffer, at);
    const auto op = FixedField<std::uint8_t>(r.fields, "op");
    if (op == kMessageData) {
      const auto connection = FixedField<std::uint32_t>(r.fields, "conn");
      const BagTime time = TimeField(r.fields, "time");
      const std::size_t slot = CheckMessage(info, connection, time);
      ++found[connection];
      if (wanted.count(connection) != 0) {
        entries.push_back({time, static_cast<std::uint32_t>(chunk), static_cast<std::uint32_t>(at),
                           static_cast<std::uint32_t>(slot)});
      }
    } else if (op != kConnection) {  // a chunk holds messages and the connections they use
      throw Error("the chunk" + At(info.position) + " holds a record of op " + std::to_string(op) +
                  " at offset " + std::to_string(at));
    }
    at = r.end;
  }
  for (const auto& [connection, messages] : info.messages) {
    if (found[connection] != messages) {
      throw Error("the chunk" + At(info.position) + " holds " + std::to_string(found[connection]) +
                  " messages of connection " + std::to_string(connection) + ", its index says " +
                  std::to_string(messages));
    }
  }
}

std::vector<BagContainer::MessageEntry> BagContainer::IndexMessages(
    File& file, const std::set<std::uint32_t>& wanted) const {
  std::vector<MessageEntry> entries;
  for (std::size_t chunk = 0; chunk < chunks_.size(); ++chunk) {
    const auto& held = chunks_[chunk].messages;
    const bool needed = std::any_of(held.begin(), held.end(),
                                    [&](const auto& c) { return wanted.count(c.first) != 0; });
    if (needed) ScanChunk(LoadChunk(file, chunk), chunk, wanted, entries);
  }
  std::sort(entries.begin(), entries.end());
  return entries;
}

void BagContainer::ForEachMessage(const std::set<std::uint32_t>& wanted, const Visit& visit) const {
  File file(path_);
  const std::vector<MessageEntry> entries =
      Damaged(path_, [&] { return IndexMessages(file, wanted); });
  // One decompressed chunk at a time, as rosbag keeps it: messages in time order mostly come
  // chunk after chunk.
  std::size_t loaded = chunks_.size();
  std::string buffer;
  for (const MessageEntry& e : entries) {
    const std::string_view data = Damaged(path_, [&] {
      if (e.chunk != loaded) {
        buffer = LoadChunk(file, e.chunk);
        loaded = e.chunk;
      }
      const MemoryRecord r = ParseRecordAt(buffer, e.offset);
      // Scanned a moment ago: anything else means the file changed while it was being read.
      if (FixedField<std::uint8_t>(r.fields, "op") != kMessageData ||
          FixedField<std::uint32_t>(r.fields, "conn") != connections_[e.slot].id) {
        throw Error("the chunk" + At(chunks_[e.chunk].position) + " changed while it was read");
      }
      return r.data;
    });
    visit(connections_[e.slot], e.time, data);
  }
}

}  // namespace uwscan::ros
