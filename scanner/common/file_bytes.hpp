#pragma once

#include <filesystem>
#include <string>

namespace uwscan {

// "'<path>'", the way every reader names a file in its errors.
std::string QuotedPath(const std::filesystem::path& path);

// The whole file as bytes. Throws uwscan::Error "'<path>': no such file" when it is missing or
// not a regular file, or "... cannot be read" on an I/O failure.
std::string ReadFileBytes(const std::filesystem::path& path);

}  // namespace uwscan
