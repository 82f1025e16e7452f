#include "apps/output_path.hpp"

#include <unistd.h>

#include "scanner/common/error.hpp"

namespace uwscan::app {

namespace fs = std::filesystem;

void CheckOutputPath(const fs::path& output, const std::string& option, const std::vector<fs::path>& inputs) {
  const std::string name = option + " " + output.string();
  const fs::path folder = output.has_parent_path() ? output.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw Error(name + ": folder '" + folder.string() + "' does not exist");
  // access() asks the kernel, so a read-only mount counts as well as the folder's permissions.
  if (::access(folder.c_str(), W_OK) != 0) {
    throw Error(name + ": folder '" + folder.string() + "' is not writable");
  }
  if (fs::is_directory(output, ec)) throw Error(name + ": is a folder, expected a file name");
  for (const fs::path& input : inputs) {
    if (input.empty()) continue;
    const bool same = fs::weakly_canonical(output, ec) == fs::weakly_canonical(input, ec) ||
                      (fs::exists(output, ec) && fs::exists(input, ec) && fs::equivalent(output, input, ec));
    if (same) throw Error(name + ": is also an input ('" + input.string() + "'); refusing to overwrite it");
  }
}

}  // namespace uwscan::app
