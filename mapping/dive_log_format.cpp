#include "mapping/dive_log_format.hpp"

#include <utility>

namespace uwscan::mapping::dive_log_format {

std::string Quoted(const std::filesystem::path& path) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
  std::string quoted(1, '\'');
  quoted.append(path.string());
  quoted.push_back('\'');
  return quoted;
}

std::string LogName(const std::filesystem::path& path) { return "dive log " + Quoted(path); }

std::string FrameName(std::int64_t index) { return "frame " + std::to_string(index); }

void SwapBytePairs(std::vector<std::uint8_t>& bytes) {
  for (std::size_t i = 0; i + 1 < bytes.size(); i += 2) std::swap(bytes[i], bytes[i + 1]);
}

}  // namespace uwscan::mapping::dive_log_format
