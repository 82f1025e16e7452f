#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

// Every reader of outside data, as one call on a file: what the fuzzers (tests/fuzz) and
// `uwscan bench robustness` feed mutated files to. A probe reads the whole file as a user's
// command would (a dive log: header, every frame with its truth, the navigation) and returns a
// count of what it read; it throws uwscan::Error on bad input, anything else is a bug.
namespace uwscan::bench {

struct ReaderProbe {
  std::string name;       // "cloud_ply", "dive_log", ...
  std::string extension;  // the file name the reader needs, e.g. ".ply"
  std::function<std::size_t(const std::filesystem::path&)> read;
};

const std::vector<ReaderProbe>& ReaderProbes();
// Throws uwscan::Error listing the names when `name` is not one of ReaderProbes().
const ReaderProbe& FindReaderProbe(const std::string& name);

}  // namespace uwscan::bench
