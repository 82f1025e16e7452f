#include "scanner/common/atomic_file.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("uwscan_atomic_file_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::ptrdiff_t FilesInFolder() const {
    return std::distance(fs::directory_iterator(dir_), fs::directory_iterator());
  }
  fs::path dir_;
};

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST_F(AtomicFileTest, ARegularFileIsReplacedWholeWithNothingLeftBeside) {
  const fs::path file = dir_ / "out.json";
  WriteFileAtomically(file, "first");
  WriteFileAtomically(file, "second, longer");
  EXPECT_EQ(Bytes(file), "second, longer");
  EXPECT_EQ(FilesInFolder(), 1);
}

// A pipe a reader waits on gets the bytes and stays a pipe (renaming over it left a regular file
// in its place and the reader with nothing). The reader's end is opened first, without blocking,
// so the write finds it and a regression fails instead of hanging.
TEST_F(AtomicFileTest, APipeIsWrittenIntoNotReplaced) {
  const fs::path fifo = dir_ / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  WriteFileAtomically(fifo, "report bytes");
  std::string received(64, '\0');
  const ssize_t n = ::read(reader, received.data(), received.size());
  ::close(reader);
  received.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  EXPECT_EQ(received, "report bytes");
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(FilesInFolder(), 1);
}

// A character device (a copy of /dev/null, made where the test may) stays a device: as root the
// rename put a regular file in /dev/null's place.
TEST_F(AtomicFileTest, ADeviceIsWrittenIntoNotReplaced) {
  const fs::path device = dir_ / "null";
  if (::mknod(device.c_str(), S_IFCHR | 0600, makedev(1, 3)) != 0) {
    GTEST_SKIP() << "cannot make a device node here (not root)";
  }
  WriteFileAtomically(device, std::string(100000, 'x'));
  EXPECT_TRUE(fs::is_character_file(device));
  EXPECT_EQ(FilesInFolder(), 1);
}

// A link (here two, the first relative) is written through: the file it ends at gets the bytes
// and every link stays a link (the rename put a regular file in the first link's place, and the
// file it pointed at kept the old bytes). A link to a file not yet there creates that file.
TEST_F(AtomicFileTest, ALinkIsWrittenThroughNotReplaced) {
  fs::create_directories(dir_ / "real");
  const fs::path file = dir_ / "real" / "map.json";
  WriteFileAtomically(file, "old");
  fs::create_symlink(file, dir_ / "absolute_link");
  fs::create_symlink("absolute_link", dir_ / "latest.json");
  WriteFileAtomically(dir_ / "latest.json", "new");
  EXPECT_EQ(Bytes(file), "new");
  EXPECT_TRUE(fs::is_symlink(dir_ / "latest.json"));
  EXPECT_TRUE(fs::is_symlink(dir_ / "absolute_link"));
  EXPECT_EQ(FilesInFolder(), 3);

  fs::create_symlink("real/later.json", dir_ / "dangling");
  WriteFileAtomically(dir_ / "dangling", "made");
  EXPECT_EQ(Bytes(dir_ / "real" / "later.json"), "made");
  EXPECT_TRUE(fs::is_symlink(dir_ / "dangling"));
}

// A link to an anonymous pipe (as /dev/stdout is, through /proc/self/fd/1, when the output is
// piped) is written into: followed to its end it gives "pipe:[N]", which is no path.
TEST_F(AtomicFileTest, ALinkToAPipeIsWrittenInto) {
  int ends[2];
  ASSERT_EQ(::pipe2(ends, O_NONBLOCK), 0);
  const fs::path stdout_like = dir_ / "stdout";
  fs::create_symlink("/proc/self/fd/" + std::to_string(ends[1]), stdout_like);
  WriteFileAtomically(stdout_like, "piped bytes");
  std::string received(64, '\0');
  const ssize_t n = ::read(ends[0], received.data(), received.size());
  ::close(ends[0]);
  ::close(ends[1]);
  received.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  EXPECT_EQ(received, "piped bytes");
  EXPECT_TRUE(fs::is_symlink(stdout_like));
}

TEST_F(AtomicFileTest, ALoopOfLinksIsAClearError) {
  fs::create_symlink("b", dir_ / "a");
  fs::create_symlink("a", dir_ / "b");
  try {
    WriteFileAtomically(dir_ / "a", "bytes");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("too many levels of symbolic links"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::is_symlink(dir_ / "a"));
}

}  // namespace
}  // namespace uwscan
