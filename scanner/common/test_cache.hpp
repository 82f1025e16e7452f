#pragma once

#include <cstdlib>
#include <filesystem>
#include <optional>

namespace uwscan::test {

// The folder where unit tests keep inputs that several of them share and that are slow to make
// (a fitted table, an object database). CTest runs each test in its own process; it sets
// UWSCAN_TEST_CACHE and empties that folder once before each run (CMakeLists.txt), so a test
// never reads what an older build made. Outside CTest there is none: each test makes its own.
inline std::optional<std::filesystem::path> TestCacheFolder() {
  const char* folder = std::getenv("UWSCAN_TEST_CACHE");
  if (folder == nullptr || *folder == '\0') return std::nullopt;
  return std::filesystem::path(folder);
}

}  // namespace uwscan::test
