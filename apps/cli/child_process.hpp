#pragma once

#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

// Programs a command runs beside itself (roscore, rosbag, uwscan's own commands in a bench),
// each stopped by its pid.
namespace uwscan::app {

class ChildProcess {
 public:
  // Starts argv[0] (searched in PATH) with its stdout and stderr appended to `log`, in this
  // process's environment. Throws uwscan::Error naming the program when it cannot start.
  ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log);
  ~ChildProcess();  // a child still running gets SIGINT, then SIGKILL after 10 s
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  struct Exit {
    int exit_code = -1;  // -1 when a signal ended it
    double cpu_s = 0.0;  // user + system CPU time of the child
    std::int64_t max_rss_bytes = 0;
  };
  // Waits for the child to end (at most `timeout_s`, then SIGKILL and an error naming it).
  Exit Wait(double timeout_s);
  void Interrupt();  // SIGINT
  pid_t pid() const { return pid_; }

 private:
  std::string name_;
  pid_t pid_ = -1;
};

// Runs argv to its end (at most `timeout_s`) and throws uwscan::Error naming it and `log` when
// it does not exit with 0.
void RunToEnd(const std::vector<std::string>& argv, const std::filesystem::path& log,
              double timeout_s);

}  // namespace uwscan::app
