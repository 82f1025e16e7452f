// Faults that must lose nothing (issue 14, item 5): outputs that cannot or must not be written
// are refused before any work; a full disk or a read-only folder gives a clear error and leaves
// no half-written file; a command killed at any moment leaves the old output or a complete new
// one. The folder faults run in a private mount namespace (tmpfs mounts of their own), as CI
// does as root; without one the tests fail saying why.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>

#include "tests/cli_run.hpp"

namespace uwscan::test {
namespace {

namespace fs = std::filesystem;

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string Scene(const char* name) { return std::string(UWSCAN_SOURCE_DIR) + "/data/scenes/" + name; }

class CliFaults : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("uwscan_cli_faults_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ASSERT_EQ(RunUwscan("simulate " + Scene("default.yaml") + " -o " + (dir_ / "dive.db").string()).exit_code, 0);
    ASSERT_EQ(RunUwscan("reconstruct " + (dir_ / "dive.db").string() + " -o " + (dir_ / "cloud.ply").string())
                  .exit_code, 0);
    ASSERT_EQ(RunUwscan("reconstruct " + (dir_ / "dive.db").string() + " --method plane --ascii -o " +
                        (dir_ / "old.ply").string()).exit_code, 0);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // A shell command line run in a private mount namespace with a tmpfs at `folder`.
  static CommandRun InTmpfs(const fs::path& folder, const std::string& options, const std::string& commands) {
    fs::create_directories(folder);
    return RunCommand("unshare -m sh -c 'mount -t tmpfs -o " + options + " tmpfs " + folder.string() + " && " +
                      commands + "'");
  }

  static inline fs::path dir_;
};

TEST_F(CliFaults, OutputsThatCannotBeWrittenAreRefusedBeforeAnyWork) {
  const std::string dive = (dir_ / "dive.db").string(), cloud = (dir_ / "cloud.ply").string();
  const std::string missing = (dir_ / "no" / "such" / "folder").string();
  struct Case {
    std::string arguments;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"simulate " + Scene("default.yaml") + " -o " + missing + "/d.db", "does not exist"},
      {"reconstruct " + dive + " -o " + missing + "/c.ply", "does not exist"},
      {"reconstruct " + dive + " -o " + cloud + " --json " + dive, "is also an input"},
      {"reconstruct " + dive + " -o " + dir_.string(), "is a folder"},
      {"register " + cloud + " " + (dir_ / "old.ply").string() + " -o " + cloud, "is also an input"},
      {"map " + dive + " -o " + missing + "/m.ply", "does not exist"},
      {"map " + dive + " -o " + (dir_ / "m.ply").string() + " --trajectory " + dive, "is also an input"},
      {"build-db pipe -o " + missing + "/o.db", "does not exist"},
      {"acquire --camera 127.0.0.1 -o " + missing + "/a.db --frames 1", "does not exist"},
      {"log salvage " + dive + " -o " + dive, "is also an input"},
  };
  for (const Case& c : cases) {
    const auto start = std::chrono::steady_clock::now();
    const CommandRun run = RunUwscan(c.arguments);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_NE(run.exit_code, 0) << c.arguments;
    EXPECT_NE(run.output.find(c.expected), std::string::npos) << c.arguments << "\n" << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << c.arguments << "\n" << run.output;
    // Refused before the work starts (the slowest of these takes tens of seconds when it runs).
    EXPECT_LT(seconds, 5.0) << c.arguments;
  }
  EXPECT_FALSE(fs::exists(dir_ / "m.ply"));
  EXPECT_TRUE(fs::is_regular_file(dive));
}

TEST_F(CliFaults, AReadOnlyFolderIsRefusedBeforeAnyWork) {
  const fs::path folder = dir_ / "read_only";
  const CommandRun run = InTmpfs(folder, "ro", std::string(UWSCAN_BIN) + " reconstruct " + (dir_ / "dive.db").string() +
                                                   " -o " + (folder / "c.ply").string());
  ASSERT_EQ(run.output.find("unshare:"), std::string::npos) << "no private mount namespace (CI runs as root): " << run.output;
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("is not writable"), std::string::npos) << run.output;
}

TEST_F(CliFaults, AFullDiskGivesAClearErrorAndKeepsTheOldFile) {
  const fs::path folder = dir_ / "full";
  const std::string bin = UWSCAN_BIN;
  // 1 MiB: the old file fits, the new cloud (a few MB) does not, nor does a dive log.
  const std::string commands =
      "printf old-cloud > " + folder.string() + "/c.ply; " +
      bin + " reconstruct " + (dir_ / "dive.db").string() + " -o " + folder.string() + "/c.ply; echo exit=$?; " +
      bin + " simulate " + Scene("default.yaml") + " -o " + folder.string() + "/d.db; echo exit=$?; " +
      "echo files: $(ls -A " + folder.string() + "); [ \"$(cat " + folder.string() +
      "/c.ply)\" = old-cloud ] && echo old-file-intact";
  const CommandRun run = InTmpfs(folder, "size=1m", commands);
  ASSERT_EQ(run.output.find("unshare:"), std::string::npos) << "no private mount namespace: " << run.output;
  EXPECT_EQ(run.output.find("exit=0"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("No space left on device"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("old-file-intact"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("files: c.ply\n"), std::string::npos) << "a half-written file was left:\n" << run.output;
}

// Kills a command at random moments over its run: the output is the old file or the new one.
void KillAtRandomMoments(const std::string& command, const fs::path& output, const std::string& old_bytes,
                         const std::string& new_bytes, double run_s, int trials) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> moment(0.0, run_s);
  for (int trial = 0; trial < trials; ++trial) {
    { std::ofstream(output, std::ios::binary) << old_bytes; }
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::execl("/bin/sh", "sh", "-c", ("exec " + command + " >/dev/null 2>&1").c_str(), nullptr);
      ::_exit(127);
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(moment(rng)));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    const std::string now = Bytes(output);
    EXPECT_TRUE(now == old_bytes || now == new_bytes)
        << command << ": killed after trial " << trial << " left " << now.size() << " bytes (old " << old_bytes.size()
        << ", new " << new_bytes.size() << ")";
  }
}

TEST_F(CliFaults, KilledAtAnyMomentTheOutputIsTheOldFileOrACompleteNewOne) {
  const std::string old_bytes = Bytes(dir_ / "old.ply");
  const std::string bin = UWSCAN_BIN;
  // reconstruct: the new cloud is known (the same command run to the end).
  const fs::path cloud = dir_ / "killed.ply";
  const std::string reconstruct = bin + " reconstruct " + (dir_ / "dive.db").string() + " -o " + cloud.string();
  KillAtRandomMoments(reconstruct, cloud, old_bytes, Bytes(dir_ / "cloud.ply"), 1.5, 8);

  // simulate --force over an older log: the output stays a readable log, old or new.
  const fs::path log = dir_ / "killed.db";
  const std::string old_log = Bytes(dir_ / "dive.db");
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    { std::ofstream(log, std::ios::binary) << old_log; }
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::execl(UWSCAN_BIN, UWSCAN_BIN, "simulate", Scene("default.yaml").c_str(), "-o", log.c_str(), "--force", nullptr);
      ::_exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100 + rng() % 1200));
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    const CommandRun check = RunUwscan("log check " + log.string());
    EXPECT_EQ(check.exit_code, 0) << check.output;
  }
}

}  // namespace
}  // namespace uwscan::test
