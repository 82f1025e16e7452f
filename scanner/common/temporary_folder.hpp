#pragma once

#include <filesystem>

namespace uwscan {

// The temporary folder: $TMPDIR, else /tmp, as std::filesystem::temp_directory_path finds it.
// Long dives spill old submaps there, the benches keep their scratch files there, and outputs
// that are devices or pipes are staged there. Throws uwscan::Error naming the folder and the
// variable when it is not a folder (the library's own exception would reach the user as an
// internal error).
std::filesystem::path TemporaryFolder();

}  // namespace uwscan
