#include "apps/cli/output_path.hpp"

#include <unistd.h>

#include "scanner/common/error.hpp"

namespace uwscan::app {

namespace fs = std::filesystem;

void CheckOutputPath(const fs::path& output, const std::string& option,
                     const std::vector<fs::path>& inputs) {
  const std::string name = option + " " + output.string();
  const fs::path folder = output.has_parent_path() ? output.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw Error(name + ": folder '" + folder.string() + "' does not exist");
  // access() asks the kernel, so a read-only mount counts as well as the folder's permissions.
  if (::access(folder.c_str(), W_OK) != 0) {
    throw Error(name + ": folder '" + folder.string() + "' is not writable");
  }
  if (fs::is_directory(output, ec)) throw Error(name + ": is a folder, expected a file name");
  std::error_code output_ec;
  const fs::path canonical_output = fs::weakly_canonical(output, output_ec);
  for (const fs::path& input : inputs) {
    if (input.empty()) continue;
    std::error_code input_ec;
    const fs::path canonical_input = fs::weakly_canonical(input, input_ec);
    // The same name once links are resolved, or the same file under another name (a hard link).
    const bool same_name = !output_ec && !input_ec && canonical_output == canonical_input;
    const bool same_file =
        fs::exists(output, ec) && fs::exists(input, ec) && fs::equivalent(output, input, ec);
    const bool same = same_name || same_file;
    if (same)
      throw Error(name + ": is also an input ('" + input.string() + "'); refusing to overwrite it");
  }
}

void CheckCloudOutputPath(const fs::path& output, const std::string& option,
                          const std::vector<fs::path>& inputs) {
  CheckOutputPath(output, option, inputs);
  const std::string extension = output.extension().string();
  if (extension != ".ply" && extension != ".pcd") {
    throw Error(option + " " + output.string() + ": a point cloud is written as .ply or .pcd");
  }
}

}  // namespace uwscan::app
