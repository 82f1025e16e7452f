#include "apps/cli/child_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "scanner/common/error.hpp"

namespace uwscan::app {

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log)
    : name_(argv.at(0)) {
  std::vector<char*> args;
  std::vector<std::string> copy = argv;
  for (std::string& a : copy) args.push_back(a.data());
  args.push_back(nullptr);
  const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (out < 0) throw Error(log.string() + ": cannot open for " + name_ + "'s output");
  pid_ = ::fork();
  if (pid_ == 0) {
    ::dup2(out, 1);
    ::dup2(out, 2);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  ::close(out);
  if (pid_ < 0) throw Error("cannot start " + name_);
}

ChildProcess::~ChildProcess() {
  if (pid_ <= 0) return;
  try {
    Interrupt();
    Wait(10.0);
  } catch (...) {
  }
}

void ChildProcess::Interrupt() {
  if (pid_ > 0) ::kill(pid_, SIGINT);
}

ChildProcess::Exit ChildProcess::Wait(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  rusage usage{};
  while (true) {
    const pid_t done = ::wait4(pid_, &status, WNOHANG, &usage);
    if (done == pid_) break;
    if (done < 0) throw Error(name_ + ": lost (wait4 failed)");
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid_, SIGKILL);
      ::wait4(pid_, &status, 0, &usage);
      pid_ = -1;
      throw Error(name_ + ": still running after " + std::to_string(timeout_s) + " s; killed");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  pid_ = -1;
  Exit e;
  e.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  e.cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
            static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
  e.max_rss_bytes = static_cast<std::int64_t>(usage.ru_maxrss) * 1024;
  return e;
}

void RunToEnd(const std::vector<std::string>& argv, const std::filesystem::path& log,
              double timeout_s) {
  ChildProcess child(argv, log);
  const ChildProcess::Exit e = child.Wait(timeout_s);
  if (e.exit_code != 0)
    throw Error(argv.at(0) + " " + (argv.size() > 1 ? argv[1] : "") + " failed (see " +
                log.string() + ")");
}

}  // namespace uwscan::app
