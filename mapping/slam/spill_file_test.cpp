#include "mapping/slam/spill_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;

class SpillFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("uwscan_spill_file_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // How many of this process's open files lie in dir_ (named or not: a nameless file's link in
  // /proc names the folder it was made in).
  int OpenFilesInFolder() const {
    int count = 0;
    for (const fs::directory_entry& fd : fs::directory_iterator("/proc/self/fd")) {
      std::error_code ignored;
      const std::string target = fs::read_symlink(fd.path(), ignored).string();
      if (target.rfind(dir_.string() + "/", 0) == 0) ++count;
    }
    return count;
  }
  fs::path dir_;
};

TEST_F(SpillFileTest, AppendsComeBackFromTheirOffsets) {
  SpillFile file(dir_, "test");
  const std::string a = "first record", b(1 << 20, 'x'), c = std::string("\0\1\2", 3);
  EXPECT_EQ(file.Append(a), 0);
  EXPECT_EQ(file.Append(""), static_cast<std::int64_t>(a.size()));
  const std::int64_t at_b = file.Append(b), at_c = file.Append(c);
  EXPECT_EQ(at_b, static_cast<std::int64_t>(a.size()));
  EXPECT_EQ(at_c, at_b + static_cast<std::int64_t>(b.size()));
  EXPECT_EQ(file.size(), at_c + 3);
  EXPECT_EQ(file.Read(at_c, 3), c);
  EXPECT_EQ(file.Read(0, static_cast<std::int64_t>(a.size())), a);
  EXPECT_EQ(file.Read(at_b, static_cast<std::int64_t>(b.size())), b);
  EXPECT_EQ(file.Read(at_b + static_cast<std::int64_t>(b.size()) - 2, 5), "xx" + c);
  EXPECT_EQ(file.Read(file.size(), 0), "");
}

TEST_F(SpillFileTest, TheFileIsInItsFolderWithoutANameAndGoesWithItsOwner) {
  {
    SpillFile file(dir_, "test");
    file.Append(std::string(4096, 'y'));
    EXPECT_TRUE(fs::is_empty(dir_));
    EXPECT_EQ(OpenFilesInFolder(), 1);
  }
  EXPECT_EQ(OpenFilesInFolder(), 0);
  EXPECT_TRUE(fs::is_empty(dir_));
}

// A process killed with its spill full (a mapper stopped mid-dive) leaves nothing in the folder.
TEST_F(SpillFileTest, AKilledProcessLeavesNothingBehind) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    SpillFile file(dir_, "test");
    file.Append(std::string(1 << 16, 'z'));
    ::raise(SIGKILL);
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "child exited " << status;
  EXPECT_TRUE(fs::is_empty(dir_));
}

// A write the disk cannot take (here the file size limit, as a full disk would refuse it) is an
// error naming the owner and the folder; what was appended before still reads back.
TEST_F(SpillFileTest, AWriteTheDiskRefusesIsNamedAndTheEarlierBytesStay) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{1 << 16, 1 << 16};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(2);
    SpillFile file(dir_, "submap store");
    const std::string first(1 << 12, 'a');
    file.Append(first);
    try {
      file.Append(std::string(1 << 20, 'b'));
      ::_exit(3);  // no error
    } catch (const Error& e) {
      const std::string message = e.what();
      if (message.find("submap store") == std::string::npos ||
          message.find(dir_.string()) == std::string::npos) {
        ::_exit(4);
      }
    }
    ::_exit(file.Read(0, 1 << 12) == first && file.size() == (1 << 12) ? 0 : 5);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "child ended by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "2: no limit, 3: no error, 4: not named, 5: bytes lost";
}

TEST_F(SpillFileTest, AMissingFolderAndAReadPastTheEndAreNamed) {
  try {
    SpillFile file(dir_ / "missing", "submap store");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("submap store"), std::string::npos) << message;
    EXPECT_NE(message.find((dir_ / "missing").string()), std::string::npos) << message;
  }
  SpillFile file(dir_, "pose graph");
  file.Append("0123456789");
  EXPECT_THROW(file.Read(8, 3), Error);
  EXPECT_THROW(file.Read(-1, 2), Error);
  try {
    file.Read(4, 20);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pose graph"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::mapping
