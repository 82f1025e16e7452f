// cmake/HashSources.cmake, which names the recognition bench's cached scans by the simulator's
// sources: the hash follows the files' contents and names, not where the tree is checked out.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "bench/recognition/recognition_scan_cache.hpp"
#include "bench/scratch_folder.hpp"

namespace uwscan::bench {
namespace {

namespace fs = std::filesystem;

void Write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// The hash HashSources.cmake gives the files `relative` under `root` (its output in `work`).
std::string HashOf(const fs::path& root, const std::vector<std::string>& relative,
                   const fs::path& work) {
  const fs::path list = work / "list.txt", output = work / "hash.cpp";
  std::ofstream out(list);
  for (const std::string& r : relative) out << (root / r).string() << "\n";
  out.close();
  const std::string script = std::string(UWSCAN_SOURCE_DIR_FOR_TESTS) + "/cmake/HashSources.cmake";
  const std::string command = "cmake -DROOT='" + root.string() + "' -DLIST='" + list.string() +
                              "' -DOUTPUT='" + output.string() + "' -DSYMBOL=kTestHash -P '" +
                              script + "'";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  std::stringstream text;
  text << std::ifstream(output).rdbuf();
  std::smatch match;
  const std::string source = text.str();
  EXPECT_TRUE(std::regex_search(source, match, std::regex("kTestHash = \"([0-9a-f]{64})\";")))
      << source;
  return match.size() > 1 ? match[1].str() : "";
}

TEST(SourceHash, FollowsContentsAndNamesNotTheCheckoutsPlace) {
  const ScratchFolder scratch("source-hash-test");
  const fs::path a = scratch.path() / "a", b = scratch.path() / "b";
  for (const fs::path& root : {a, b}) {
    Write(root / "sim/scan.cpp", "int Scan() { return 1; }\n");
    Write(root / "optics/lens.hpp", "#pragma once\n");
  }
  const std::vector<std::string> files = {"optics/lens.hpp", "sim/scan.cpp"};
  const std::string original = HashOf(a, files, scratch.path());
  ASSERT_EQ(original.size(), 64u);
  EXPECT_EQ(HashOf(b, files, scratch.path()), original);  // another checkout of the same sources

  Write(b / "sim/scan.cpp", "int Scan() { return 2; }\n");  // one byte of code changed
  EXPECT_NE(HashOf(b, files, scratch.path()), original);
  Write(b / "sim/scan.cpp", "int Scan() { return 1; }\n");
  EXPECT_EQ(HashOf(b, files, scratch.path()), original);

  fs::rename(b / "sim/scan.cpp", b / "sim/scan2.cpp");  // same bytes under another name
  EXPECT_NE(HashOf(b, {"optics/lens.hpp", "sim/scan2.cpp"}, scratch.path()), original);
}

TEST(SourceHash, TheBenchIsBuiltWithTheSimulatorsHash) {
  EXPECT_TRUE(std::regex_match(std::string(kSimulatorSourceHash), std::regex("[0-9a-f]{64}")));
}

}  // namespace
}  // namespace uwscan::bench
