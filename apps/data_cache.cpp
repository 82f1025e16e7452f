#include "apps/data_cache.hpp"

#include <cstdlib>

#include "scanner/common/error.hpp"

namespace uwscan::app {

std::filesystem::path DataCache() {
  std::filesystem::path cache;
  if (const char* env = std::getenv("UWSCAN_DATA_CACHE"); env != nullptr && *env != '\0') {
    cache = env;
  } else if (const char* home = std::getenv("HOME"); home != nullptr) {
    cache = std::filesystem::path(home) / ".cache" / "uwscan";
  }
  if (cache.empty() || !std::filesystem::is_directory(cache / "meshes") ||
      !std::filesystem::is_directory(cache / "scans")) {
    throw Error("real data not found in '" + cache.string() +
                "': run scripts/fetch_data.sh (or set UWSCAN_DATA_CACHE)");
  }
  return cache;
}

}  // namespace uwscan::app
