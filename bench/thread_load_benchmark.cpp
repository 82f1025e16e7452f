#include "bench/thread_load_benchmark.hpp"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <optional>
#include <string>
#include <thread>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

extern char** environ;

namespace uwscan::bench {
namespace {

using Clock = std::chrono::steady_clock;

// The highest-numbered CPU this process may run on.
int LastCpu() {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (::sched_getaffinity(0, sizeof(allowed), &allowed) != 0) {
    throw Error(std::string("bench threads: cannot read the CPUs allowed (") +
                std::strerror(errno) + ")");
  }
  int last = -1;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed)) last = cpu;
  }
  if (CPU_COUNT(&allowed) < 2)
    throw Error("bench threads: needs 2 CPUs or more (this process may use 1)");
  return last;
}

// Another program keeping one CPU busy: a child process pinned to the last CPU, spinning until
// it is killed (here, or by the destructor on any way out).
class SpinningProcess {
 public:
  SpinningProcess() {
    const int cpu = LastCpu();
    const pid_t parent = ::getpid();
    pid_ = ::fork();
    if (pid_ < 0)
      throw Error(std::string("bench threads: cannot start the load process (") +
                  std::strerror(errno) + ")");
    if (pid_ == 0) {
      // Never outlive the benchmark, however it ends.
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) ::_exit(0);
      cpu_set_t cpus;
      CPU_ZERO(&cpus);
      CPU_SET(cpu, &cpus);
      if (::sched_setaffinity(0, sizeof(cpus), &cpus) != 0) ::_exit(1);
      while (true) asm volatile("" ::: "memory");  // a loop the compiler must keep
    }
  }
  ~SpinningProcess() {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  SpinningProcess(const SpinningProcess&) = delete;
  SpinningProcess& operator=(const SpinningProcess&) = delete;

 private:
  pid_t pid_ = -1;
};

struct Workload {
  std::string name;
  std::vector<std::string> arguments;
};

// The environment with OMP_WAIT_POLICY and OMP_NUM_THREADS set as asked.
std::vector<std::string> ChildEnvironment(const std::string& policy, int threads) {
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    if (entry.rfind("OMP_WAIT_POLICY=", 0) == 0 || entry.rfind("OMP_NUM_THREADS=", 0) == 0)
      continue;
    env.push_back(entry);
  }
  env.push_back("OMP_WAIT_POLICY=" + policy);
  env.push_back("OMP_NUM_THREADS=" + std::to_string(threads));
  return env;
}

std::vector<char*> Pointers(std::vector<std::string>& strings) {
  std::vector<char*> pointers;
  for (std::string& s : strings) pointers.push_back(s.data());
  pointers.push_back(nullptr);
  return pointers;
}

// Runs uwscan with `arguments` and returns its wall-clock time; its output goes to `log`.
double TimedRun(const ThreadLoadOptions& options, const Workload& workload,
                const std::string& policy, int threads, const std::filesystem::path& log) {
  std::vector<std::string> argv = {options.uwscan.string()};
  argv.insert(argv.end(), workload.arguments.begin(), workload.arguments.end());
  std::vector<std::string> env = ChildEnvironment(policy, threads);
  std::vector<char*> c_argv = Pointers(argv), c_env = Pointers(env);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  const Clock::time_point start = Clock::now();
  pid_t child = -1;
  const int spawned =
      posix_spawn(&child, argv[0].c_str(), &actions, nullptr, c_argv.data(), c_env.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0)
    throw Error("bench threads: cannot run " + argv[0] + " (" + std::strerror(spawned) + ")");
  int status = 0;
  const bool waited = ::waitpid(child, &status, 0) == child;
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!waited || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string command;
    for (const std::string& a : argv) command += (command.empty() ? "" : " ") + a;
    throw Error("bench threads: `" + command + "` failed (its output: " + log.string() + ")");
  }
  return seconds;
}

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

void ThreadLoadOptions::Check() const {
  const OptionChecks check("ThreadLoadOptions");
  check.InRange("repeats", repeats, 1, 100);
  check.Require(std::filesystem::is_regular_file(uwscan), "uwscan", "the uwscan executable",
                OptionQuotedText(uwscan.string()) + " (no such file)");
  check.Require(std::filesystem::is_directory(data_dir), "data_dir", "the data folder",
                OptionQuotedText(data_dir.string()) + " (no such folder)");
}

double ThreadLoadResult::Median(const std::string& workload, const std::string& policy, bool loaded,
                                int threads) const {
  for (const ThreadLoadTiming& t : timings) {
    if (t.workload == workload && t.policy == policy && t.loaded == loaded && t.threads == threads)
      return t.median_s;
  }
  throw Error("bench threads: no timing for " + workload + ", " + policy + ", " +
              std::to_string(threads) + " threads");
}

ThreadLoadResult RunThreadLoadBenchmark(const ThreadLoadOptions& options,
                                        const std::filesystem::path& scratch,
                                        const Progress& progress) {
  options.Check();
  const Clock::time_point start = Clock::now();
  // Two commands that spend their time in OpenMP loops of different grain: the object database
  // (virtual scans, normals, ESF and FPFH per view) and a dive's simulation (ray casting per
  // frame).
  const std::vector<Workload> workloads = {
      {"build-db pipe", {"build-db", "pipe", "-o", (scratch / "objects.db").string()}},
      {"simulate inspection_short",
       {"simulate", (options.data_dir / "scenes" / "inspection_short.yaml").string(), "-o",
        (scratch / "dive.db").string(), "--force"}},
  };
  const std::vector<std::string> policies = {"PASSIVE", "ACTIVE"};
  ThreadLoadResult result;
  result.cpus = static_cast<int>(std::thread::hardware_concurrency());
  for (const bool loaded : {false, true}) {
    for (const Workload& workload : workloads) {
      for (const std::string& policy : policies) {
        for (const int threads : {1, 2})
          result.timings.push_back({workload.name, policy, loaded, threads, 0.0, {}});
      }
    }
  }
  const int total = static_cast<int>(result.timings.size()) * options.repeats;
  int done = 0;
  // Repeats go round all configurations of a load in turn, so that slow spells of a shared
  // machine spread over them rather than hitting one.
  for (const bool loaded : {false, true}) {
    std::optional<SpinningProcess> load;
    if (loaded) load.emplace();
    for (int repeat = 0; repeat < options.repeats; ++repeat) {
      for (ThreadLoadTiming& timing : result.timings) {
        if (timing.loaded != loaded) continue;
        const auto workload =
            std::find_if(workloads.begin(), workloads.end(),
                         [&](const Workload& w) { return w.name == timing.workload; });
        timing.runs_s.push_back(
            TimedRun(options, *workload, timing.policy, timing.threads, scratch / "command.log"));
        if (progress)
          progress(loaded ? "other CPU loaded" : "idle", static_cast<double>(++done) / total);
      }
    }
  }
  for (ThreadLoadTiming& timing : result.timings) timing.median_s = Median(timing.runs_s);
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace uwscan::bench
