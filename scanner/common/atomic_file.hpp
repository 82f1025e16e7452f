#pragma once

#include <filesystem>
#include <string_view>

// Files that are replaced whole or not at all: written under a temporary name beside the target
// (same file system, so the rename is atomic) and renamed over it when complete. A failure, a
// full disk or a process killed at any moment leaves the earlier file (or none) and never half
// of a new one. A target that is a device or a pipe (/dev/null, a FIFO a reader waits on) is not
// replaced, which would put a regular file in its place (as root, /dev/null itself): the
// temporary goes to the temporary folder and its bytes are written into the target. A target
// that is a symbolic link is written through: the file it ends at is replaced, the link stays.
namespace uwscan {

// Where a write to `path` lands: `path`, or the file its chain of symbolic links ends at (which
// need not exist yet); `path` itself when it leads to a device or a pipe (/dev/stdout). Throws
// uwscan::Error on a loop of links.
std::filesystem::path FollowLinks(const std::filesystem::path& path);

// The temporary name `path` is written under: in its folder, hidden, unique to this call
// ("folder/.name.part-PID-N"), the folder of the file a link ends at (FollowLinks); in the
// temporary folder when `path` is a device or a pipe.
std::filesystem::path TemporaryBeside(const std::filesystem::path& path);

// Flushes `temporary` to disk, renames it over `path` and syncs the folder; when `path` is a
// device or a pipe, writes the temporary's bytes into it instead and removes the temporary. On
// failure removes the temporary and throws uwscan::Error naming `path`.
void ReplaceWithTemporary(const std::filesystem::path& temporary,
                          const std::filesystem::path& path);

// Writes `bytes` (text or binary) to path through TemporaryBeside and ReplaceWithTemporary.
// Throws uwscan::Error naming the path (and the system's reason: no space left, read-only, ...).
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace uwscan
