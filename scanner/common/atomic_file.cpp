#include "scanner/common/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/common/temporary_folder.hpp"

namespace uwscan {
namespace {

namespace fs = std::filesystem;

// fsync by name; false with errno set when the file cannot be opened or synced.
bool Sync(const fs::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return false;
  const bool synced = ::fsync(fd) == 0 || errno == EINVAL;  // EINVAL: cannot be synced (a pipe)
  ::close(fd);
  return synced;
}

// Whether `path` exists and is a device, a pipe or a socket: written into, never replaced.
bool IsSpecialFile(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  return !ec && fs::exists(status) && !fs::is_regular_file(status) && !fs::is_directory(status);
}

// Writes the bytes of `temporary` into the special file `path`; "" when all were written, else
// why not.
std::string CopyInto(const fs::path& temporary, const fs::path& path) {
  std::FILE* in = std::fopen(temporary.c_str(), "rb");
  if (in == nullptr) return std::strerror(errno);
  std::FILE* out = std::fopen(path.c_str(), "wb");
  if (out == nullptr) {
    const std::string reason = std::strerror(errno);
    std::fclose(in);
    return reason;
  }
  std::array<char, 1 << 16> buffer;
  bool written = true;
  while (const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), in)) {
    if (std::fwrite(buffer.data(), 1, n, out) != n) {
      written = false;
      break;
    }
  }
  const int write_errno = errno;
  const bool read = std::ferror(in) == 0;
  std::fclose(in);
  const bool closed = std::fclose(out) == 0;
  if (written && read && closed) return "";
  return std::strerror(written ? errno : write_errno);
}

}  // namespace

fs::path FollowLinks(const fs::path& path) {
  // A link to a device or a pipe (/dev/stdout to /proc/self/fd/1 to "pipe:[N]", which is no
  // path) is written into through the link itself.
  if (IsSpecialFile(path)) return path;
  // Linux itself gives up after 40 links in one path.
  constexpr int kMaxLinks = 40;
  fs::path target = path;
  std::error_code ec;
  for (int links = 0; fs::is_symlink(fs::symlink_status(target, ec)); ++links) {
    if (links == kMaxLinks) throw Error(path.string() + ": too many levels of symbolic links");
    const fs::path next = fs::read_symlink(target, ec);
    if (ec) throw Error(path.string() + ": cannot read the symbolic link (" + ec.message() + ")");
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  return target;
}

fs::path TemporaryBeside(const fs::path& link_or_path) {
  const fs::path path = FollowLinks(link_or_path);
  static std::atomic<unsigned> count{0};  // two writes of one process never share a name
  std::string name = ".";
  name += path.filename().string();
  name += ".part-";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(count++);
  return (IsSpecialFile(path) ? TemporaryFolder() : path.parent_path()) / name;
}

void ReplaceWithTemporary(const fs::path& temporary, const fs::path& link_or_path) {
  const fs::path path = FollowLinks(link_or_path);
  std::error_code ec;
  if (IsSpecialFile(path)) {
    const std::string reason = CopyInto(temporary, path);
    fs::remove(temporary, ec);
    if (!reason.empty()) throw Error(path.string() + ": cannot write (" + reason + ")");
    return;
  }
  if (!Sync(temporary, O_RDONLY)) {
    const std::string reason = std::strerror(errno);
    fs::remove(temporary, ec);
    throw Error(path.string() + ": cannot write (" + reason + ")");
  }
  fs::rename(temporary, path, ec);
  if (ec) {
    const std::string reason = ec.message();
    fs::remove(temporary, ec);
    throw Error(path.string() + ": cannot replace the file (" + reason + ")");
  }
  // The rename itself survives a power cut only once the folder is synced; some file systems
  // refuse to sync a folder, which is no reason to fail a write that happened.
  Sync(path.has_parent_path() ? path.parent_path() : fs::path("."), O_RDONLY | O_DIRECTORY);
}

void WriteFileAtomically(const fs::path& path, std::string_view bytes) {
  const fs::path temporary = TemporaryBeside(path);
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) throw Error(path.string() + ": cannot write (" + std::strerror(errno) + ")");
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  const int write_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) {
    const std::string reason = std::strerror(written ? errno : write_errno);
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw Error(path.string() + ": cannot write (" + reason + ")");
  }
  ReplaceWithTemporary(temporary, path);
}

}  // namespace uwscan
