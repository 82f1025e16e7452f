#pragma once
// What the camera tests (cli_acquisition_test, cli_inspect_test) share: `uwscan` processes in
// the background (the fake camera), temporary files, JSON, cloud comparisons and lost frames.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "mapping/log/dive_log.hpp"

extern char** environ;

namespace uwscan::test {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

inline std::string SourcePath(const std::string& relative) {
  return std::string(UWSCAN_SOURCE_DIR) + "/" + relative;
}

inline std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// A `uwscan` process in the background, its output in a file.
class Background {
 public:
  Background(const std::vector<std::string>& args, const fs::path& output) : output_(output) {
    std::vector<std::string> argv = {UWSCAN_BIN};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> c_argv;
    for (std::string& a : argv) c_argv.push_back(a.data());
    c_argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, output.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    const int rc = posix_spawn(&pid_, UWSCAN_BIN, &actions, nullptr, c_argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) pid_ = -1;
  }
  ~Background() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  // Waits until the output holds `text`; false after `seconds` or when the process ended.
  bool WaitFor(const std::string& text, double seconds) const {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) {
      if (Output().find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  void Signal(int signal) const { kill(pid_, signal); }
  // Exit code (-signal when killed by one).
  int Wait() {
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  }
  std::string Output() const { return ReadFile(output_); }

 private:
  pid_t pid_ = -1;
  fs::path output_;
};

// `uwscan fake-camera ...` in the background, once it serves; its output in `log`.
inline std::unique_ptr<Background> StartFakeCameraLogged(const std::vector<std::string>& args,
                                                         const fs::path& log) {
  auto camera = std::make_unique<Background>(args, log);
  EXPECT_TRUE(camera->WaitFor("serving", 60.0)) << camera->Output();
  return camera;
}

// An ASCII PLY's vertices (x y z first on each line).
inline std::vector<Eigen::Vector3d> ReadAsciiPly(const fs::path& path) {
  std::vector<Eigen::Vector3d> points;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line.rfind("end_header", 0) != 0) {
  }
  while (std::getline(in, line)) {
    std::istringstream s(line);
    Eigen::Vector3d p;
    if (s >> p.x() >> p.y() >> p.z()) points.push_back(p);
  }
  return points;
}

// Largest distance from a point of `a` to its nearest point of `b`, searched on a grid of
// `cell` metres (the 27 cells around a point): distances beyond `cell` come out as 1 m.
inline double MaxNearestDistance(const std::vector<Eigen::Vector3d>& a,
                                 const std::vector<Eigen::Vector3d>& b, double cell = 1e-3) {
  auto key = [cell](const Eigen::Vector3d& p, int dx, int dy, int dz) {
    const auto i = static_cast<std::int64_t>(std::floor(p.x() / cell)) + dx;
    const auto j = static_cast<std::int64_t>(std::floor(p.y() / cell)) + dy;
    const auto k = static_cast<std::int64_t>(std::floor(p.z() / cell)) + dz;
    return (i * 73856093) ^ (j * 19349663) ^ (k * 83492791);
  };
  std::unordered_multimap<std::int64_t, std::size_t> grid;
  for (std::size_t i = 0; i < b.size(); ++i) grid.emplace(key(b[i], 0, 0, 0), i);
  double worst = 0.0;
  for (const Eigen::Vector3d& p : a) {
    double best = 1.0;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto [first, last] = grid.equal_range(key(p, dx, dy, dz));
          for (auto it = first; it != last; ++it) best = std::min(best, (b[it->second] - p).norm());
        }
    worst = std::max(worst, best);
  }
  return worst;
}

// What a log of the fake camera's default scene says of the frames it sent: each frame carries
// the camera's frame counter as its sweep and mirror step (201 steps a sweep), so the counter's
// gaps between the first and the last logged frame are the frames lost on the way.
struct CounterGaps {
  std::int64_t logged = 0;
  std::int64_t missing = 0;
  bool in_order = true;  // the counter never runs backwards
};
inline CounterGaps CounterGapsOf(const fs::path& log) {
  std::vector<std::int64_t> counters;
  mapping::DiveLogReader(log).ForEachFrame(
      [&](const mapping::FrameRecord& f, const mapping::GroundTruthRecord*) {
        counters.push_back(static_cast<std::int64_t>(f.sweep) * 201 + (f.command + 100));
      },
      false);
  CounterGaps g;
  g.logged = static_cast<std::int64_t>(counters.size());
  g.in_order = std::is_sorted(counters.begin(), counters.end());
  if (!counters.empty()) g.missing = counters.back() - counters.front() + 1 - g.logged;
  return g;
}

}  // namespace uwscan::test
