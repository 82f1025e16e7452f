#include "mapping/slam/spill_file.hpp"

#include <unistd.h>

#include <atomic>
#include <fstream>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {

std::filesystem::path NewSpillFile(const std::filesystem::path& folder, const std::string& stem,
                                   const std::string& owner) {
  static std::atomic<int> counter{0};
  const std::filesystem::path path = folder / (stem + "-" + std::to_string(::getpid()) + "-" +
                                               std::to_string(counter.fetch_add(1)) + ".bin");
  std::ofstream create(path, std::ios::binary | std::ios::trunc);
  if (!create) {
    throw Error(owner + ": cannot create the spill file " + path.string() +
                " (is the folder there and writable?)");
  }
  return path;
}

}  // namespace uwscan::mapping
