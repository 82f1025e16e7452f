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

std::string ReadFileBytes(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(QuotedPath(path) + ": no such file");
  std::ifstream in(path, std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (!in && !in.eof()) throw Error(QuotedPath(path) + ": cannot be read");
  return bytes;
}

}  // namespace uwscan
