#pragma once

#include <filesystem>
#include <string>

namespace uwscan::mapping {

// Creates an empty spill file in `folder`, named from `stem`, the process and a counter, so that
// every spill (several mappers, graphs and stores in one process, several processes) has its own.
// Its owner writes to it and removes it. Throws uwscan::Error naming `owner` and the path when the
// file cannot be created.
std::filesystem::path NewSpillFile(const std::filesystem::path& folder, const std::string& stem,
                                   const std::string& owner);

}  // namespace uwscan::mapping
