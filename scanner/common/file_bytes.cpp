#include "scanner/common/file_bytes.hpp"

#include <fstream>
#include <iterator>
#include <system_error>

#include "scanner/common/error.hpp"

namespace uwscan {

std::string QuotedPath(const std::filesystem::path& path) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
  std::string quoted(1, '\'');
  quoted.append(path.string());
  quoted.push_back('\'');
  return quoted;
}

void RequireRegularFile(const std::filesystem::path& path, const std::string& name) {
  const std::string named = name.empty() ? QuotedPath(path) : name;
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::is_regular_file(status)) return;
  if (ec && ec != std::errc::no_such_file_or_directory) {
    throw Error(named + ": cannot be examined (" + ec.message() + ")");
  }
  if (!std::filesystem::exists(status)) throw Error(named + ": no such file");
  if (std::filesystem::is_directory(status)) throw Error(named + ": a directory, not a file");
  throw Error(named + ": not a regular file (a pipe, device or socket)");
}

bool IsRegularFile(const std::filesystem::path& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

std::string ReadFileBytes(const std::filesystem::path& path) {
  RequireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (!in && !in.eof()) throw Error(QuotedPath(path) + ": cannot be read");
  return bytes;
}

}  // namespace uwscan
