#pragma once
// Running the `uwscan` program from the end-to-end tests, the way a user does.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace uwscan::test {

struct CommandRun {
  int exit_code;
  std::string output;  // stdout and stderr
};

// Any shell command line, stdout and stderr captured.
inline CommandRun RunCommand(const std::string& command_line) {
  const std::string command = command_line + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "popen failed"};
  std::string output;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

inline CommandRun RunUwscan(const std::string& arguments) {
  return RunCommand(std::string(UWSCAN_BIN) + " " + arguments);
}

// A folder of this test process's own in the temporary directory, emptied on first use and
// removed with everything in it when the process ends (kept when UWSCAN_KEEP_TEST_FILES is set,
// to look into a failure). CTest runs each test as a process of its own: a file named by the
// process id alone would stay behind after every run.
inline const std::filesystem::path& ScratchFolder() {
  static const struct Folder {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() /
        (std::string("uwscan_") + program_invocation_short_name + "_" + std::to_string(getpid()));
    Folder() {
      std::filesystem::remove_all(path);
      std::filesystem::create_directories(path);
    }
    ~Folder() {
      std::error_code ignored;
      if (std::getenv("UWSCAN_KEEP_TEST_FILES") == nullptr)
        std::filesystem::remove_all(path, ignored);
    }
  } folder;
  return folder.path;
}

inline std::filesystem::path ScratchPath(const std::string& name) { return ScratchFolder() / name; }

}  // namespace uwscan::test
