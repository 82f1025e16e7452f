#pragma once

#include <filesystem>
#include <string>

namespace uwscan {

// Writes text to path through a temporary file beside it (path + ".part") and a rename: a
// failure or a crash leaves any earlier file untouched. Throws uwscan::Error naming the path.
void WriteTextAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace uwscan
