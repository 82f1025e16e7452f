#include "apps/cli/data_folder.hpp"

#include <cstdlib>
#include <system_error>

#include "scanner/common/error.hpp"

namespace uwscan::app {
namespace {

namespace fs = std::filesystem;

// share/uwscan beside the running executable's bin/ (UWSCAN_INSTALLED_DATA_FROM_BIN is that path
// relative to bin/, from the install layout in CMake); empty when the executable cannot be named.
fs::path InstalledDataFolder() {
  std::error_code error;
  const fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (error) return {};
  return (executable.parent_path() / UWSCAN_INSTALLED_DATA_FROM_BIN).lexically_normal();
}

}  // namespace

fs::path DataFolder() {
  if (const char* env = std::getenv("UWSCAN_DATA_DIR"); env != nullptr && *env != '\0') {
    if (!fs::is_directory(env))
      throw Error(std::string("UWSCAN_DATA_DIR=") + env + ": not a folder");
    return env;
  }
  const fs::path installed = InstalledDataFolder();
  if (!installed.empty() && fs::is_directory(installed)) return installed;
  const fs::path source = UWSCAN_SOURCE_DATA_DIR;
  if (fs::is_directory(source)) return source;
  throw Error("uwscan's data folder not found: UWSCAN_DATA_DIR is not set, and neither '" +
              installed.string() + "' (installed) nor '" + source.string() +
              "' (source tree) is a folder; set UWSCAN_DATA_DIR");
}

fs::path DataFolderOr(const std::string& given) {
  return given.empty() ? DataFolder() : fs::path(given);
}

}  // namespace uwscan::app
