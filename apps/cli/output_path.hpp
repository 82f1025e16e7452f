#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace uwscan::app {

// Refuses, before any work is done, an output the command could not write or must not: its
// folder is missing or not writable, it is a folder, or it is one of `inputs` (the same file by
// name or by identity). `option` names it in the one-line error ("-o", "--json").
void CheckOutputPath(const std::filesystem::path& output, const std::string& option,
                     const std::vector<std::filesystem::path>& inputs = {});

// CheckOutputPath for a point cloud, which uwscan writes as .ply or .pcd only: another extension
// is refused too, before the work rather than after it.
void CheckCloudOutputPath(const std::filesystem::path& output, const std::string& option,
                          const std::vector<std::filesystem::path>& inputs = {});

}  // namespace uwscan::app
