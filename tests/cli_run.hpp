#pragma once
// Running the `uwscan` program from the end-to-end tests, the way a user does.
#include <sys/wait.h>

#include <array>
#include <cstdio>
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

}  // namespace uwscan::test
