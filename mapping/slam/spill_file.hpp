#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace uwscan::mapping {

// A scratch file for what a long dive moves out of memory (old submaps' clouds, old graph
// measurements): created in a folder but given no name there, so that it takes that folder's disk
// and never outlives the process, however the process ends (a mapper killed mid-dive leaves no
// gigabytes behind). Written by appending, read back at the offsets the appends returned. Not
// thread-safe.
class SpillFile {
 public:
  // Throws uwscan::Error naming `owner` and `folder` when no file can be created there.
  SpillFile(const std::filesystem::path& folder, std::string owner);
  ~SpillFile();
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  // Appends `bytes` and returns the offset they start at. Throws uwscan::Error when the write
  // fails (a full disk).
  std::int64_t Append(std::string_view bytes);
  // The `size` bytes at `offset`. Throws uwscan::Error when they cannot be read back (beyond the
  // end, or an I/O error).
  std::string Read(std::int64_t offset, std::int64_t size) const;
  // The bytes appended so far.
  std::int64_t size() const { return size_; }

 private:
  std::filesystem::path folder_;
  std::string owner_;
  int fd_ = -1;
  std::int64_t size_ = 0;
};

}  // namespace uwscan::mapping
