#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include "scanner/sim/virtual_scanner.hpp"

namespace uwscan::bench {

// Simulated scans of the recognition bench kept on disk between runs, so that comparing two
// versions of the recogniser does not simulate the same 100 scenes again (most of a no-peers
// run). A scan is found by `key`, a hash of everything it depends on: the scene, seed and
// rendering the bench chose, and the simulator's code (kSimulatorSourceHash), so that a scan
// simulated by other code is never read back. Only the points and their object indices are kept
// (truth_C is left empty).
// The SHA-256 (hex) of the sources a simulated scan depends on: the scanner's code other than its
// tests, calibration and acquisition, and its default configurations (bench/CMakeLists.txt,
// computed at build time by cmake/HashSources.cmake).
extern const char* const kSimulatorSourceHash;

struct CachedScanKey {
  int scan = 0;
  std::uint64_t key = 0;
};

// The cached scan, or none when there is no file for it. Throws uwscan::Error naming the file
// when it is there but truncated, damaged or of another format version.
std::optional<scanner::sim::VirtualScan> LoadCachedScan(const std::filesystem::path& folder,
                                                        const CachedScanKey& key);

// Writes the scan (to a temporary file renamed into place: a reader sees a whole file or none).
// Throws uwscan::Error when the folder cannot be written.
void SaveCachedScan(const std::filesystem::path& folder, const CachedScanKey& key,
                    const scanner::sim::VirtualScan& scan);

}  // namespace uwscan::bench
