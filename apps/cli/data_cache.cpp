#include "apps/cli/data_cache.hpp"

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

std::filesystem::path TableCache() {
  const auto env = [](const char* name) -> const char* {
    const char* value = std::getenv(name);
    return value != nullptr && *value != '\0' ? value : nullptr;
  };
  if (const char* dir = env("UWSCAN_TABLE_CACHE")) return dir;
  if (const char* xdg = env("XDG_CACHE_HOME"))
    return std::filesystem::path(xdg) / "uwscan" / "tables";
  if (const char* home = env("HOME"))
    return std::filesystem::path(home) / ".cache" / "uwscan" / "tables";
  return {};
}

}  // namespace uwscan::app
