#include "mapping/slam/spill_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// An open file in `folder` with no name: O_TMPFILE where the file system has it, else a unique
// name removed at once (the file then has a name for the microseconds between the two calls).
// -1 with errno set when neither works.
int OpenNameless(const std::filesystem::path& folder) {
  const int fd = ::open(folder.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd >= 0 || (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL)) return fd;
  std::string name = (folder / "uwscan-spill-XXXXXX").string();
  const int named = ::mkostemp(name.data(), O_CLOEXEC);
  if (named >= 0) ::unlink(name.c_str());
  return named;
}

// Calls io(done) until `count` bytes are moved (pread and pwrite may move fewer at a time, or be
// interrupted): "" when they all were, else why not.
template <typename Io>
std::string MoveAll(std::size_t count, Io io) {
  std::size_t done = 0;
  while (done < count) {
    const ssize_t n = io(done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return std::strerror(errno);
    if (n == 0) return "no byte moved (end of file)";
    done += static_cast<std::size_t>(n);
  }
  return "";
}

off_t At(std::int64_t offset, std::size_t done) {
  return static_cast<off_t>(offset + static_cast<std::int64_t>(done));
}

}  // namespace

SpillFile::SpillFile(const std::filesystem::path& folder, std::string owner)
    : folder_(folder), owner_(std::move(owner)), fd_(OpenNameless(folder)) {
  if (fd_ < 0) {
    throw Error(owner_ + ": cannot create a spill file in " + folder.string() + " (" +
                std::strerror(errno) + "; is the folder there and writable?)");
  }
}

SpillFile::~SpillFile() { ::close(fd_); }

std::int64_t SpillFile::Append(std::string_view bytes) {
  const std::int64_t offset = size_;
  const std::string failed = MoveAll(bytes.size(), [&](std::size_t done) {
    return ::pwrite(fd_, bytes.data() + done, bytes.size() - done, At(offset, done));
  });
  if (!failed.empty()) {
    throw Error(owner_ + ": cannot write to its spill file in " + folder_.string() + " (" + failed +
                "; disk full?)");
  }
  size_ += static_cast<std::int64_t>(bytes.size());
  return offset;
}

std::string SpillFile::Read(std::int64_t offset, std::int64_t size) const {
  if (offset < 0 || size < 0 || offset + size > size_) {
    throw Error(owner_ + ": asked its spill file for bytes " + std::to_string(offset) + " to " +
                std::to_string(offset + size) + " of " + std::to_string(size_));
  }
  std::string bytes(static_cast<std::size_t>(size), '\0');
  const std::string failed = MoveAll(bytes.size(), [&](std::size_t done) {
    return ::pread(fd_, bytes.data() + done, bytes.size() - done, At(offset, done));
  });
  if (!failed.empty()) {
    throw Error(owner_ + ": cannot read its spill file in " + folder_.string() + " back (" +
                failed + ")");
  }
  return bytes;
}

}  // namespace uwscan::mapping
