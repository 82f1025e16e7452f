#pragma once

#include <filesystem>
#include <string>

namespace uwscan {

// "'<path>'", the way every reader names a file in its errors.
std::string QuotedPath(const std::filesystem::path& path);

// Throws uwscan::Error "<name>: no such file", "<name>: a directory, not a file" or "<name>: not
// a regular file (a pipe, device or socket)" unless `path` is a regular file (or a link to one).
// Checked before a reader opens a file: a pipe with no writer would block it for ever.
// `name` is how the caller names the file ("'<path>' (read as PLY)"); QuotedPath(path) if empty.
void RequireRegularFile(const std::filesystem::path& path, const std::string& name = "");

// Whether `path` is a regular file (or a link to one); false, never throwing, otherwise.
bool IsRegularFile(const std::filesystem::path& path);

// The whole file as bytes. Throws uwscan::Error as RequireRegularFile does, or "... cannot be
// read" on an I/O failure.
std::string ReadFileBytes(const std::filesystem::path& path);

}  // namespace uwscan
