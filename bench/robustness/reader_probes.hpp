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

// A folder where mutated inputs are read as a user's files would be: `scanners/` holds copies
// of data_dir/scanners (scenes name them as ../scanners/NAME.yaml) and `inputs/` three small
// greyscale images that calibration manifests may name (v0.png .. v2.png).
void PrepareReaderWorkspace(const std::filesystem::path& workspace,
                            const std::filesystem::path& data_dir);
// Where `probe`'s input goes in a workspace: inputs/input.EXT, or inputs/NAME for a probe whose
// extension is a whole file name (manifest.yaml).
std::filesystem::path ReaderInputPath(const ReaderProbe& probe,
                                      const std::filesystem::path& workspace);

}  // namespace uwscan::bench
