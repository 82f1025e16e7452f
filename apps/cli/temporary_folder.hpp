#pragma once

#include <filesystem>

namespace uwscan::app {

// The folder commands spill to on long dives (old submaps' clouds, old graph measurements):
// $TMPDIR, else /tmp, as std::filesystem::temp_directory_path finds it. Throws uwscan::Error
// naming the folder and the variable when it is not a folder (the library's own error would
// reach the user as an internal error).
std::filesystem::path TemporaryFolder();

}  // namespace uwscan::app
