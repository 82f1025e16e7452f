#pragma once

#include <filesystem>
#include <string_view>

// Files that are replaced whole or not at all: written under a temporary name beside the target
// (same file system, so the rename is atomic) and renamed over it when complete. A failure, a
// full disk or a process killed at any moment leaves the earlier file (or none) and never half
// of a new one.
namespace uwscan {

// The temporary name `path` is written under: in its folder, hidden, unique to this call
// ("folder/.name.part-PID-N").
std::filesystem::path TemporaryBeside(const std::filesystem::path& path);

// Flushes `temporary` to disk, renames it over `path` and syncs the folder. On failure removes
// the temporary and throws uwscan::Error naming `path`.
void ReplaceWithTemporary(const std::filesystem::path& temporary,
                          const std::filesystem::path& path);

// Writes `bytes` (text or binary) to path through TemporaryBeside and ReplaceWithTemporary.
// Throws uwscan::Error naming the path (and the system's reason: no space left, read-only, ...).
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace uwscan
