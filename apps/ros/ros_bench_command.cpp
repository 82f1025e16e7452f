#include "apps/ros/ros_bench_command.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "apps/cli/child_process.hpp"
#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/output_path.hpp"
#include "bench/slam/long_dive_benchmark.hpp"
#include "bench/slam/long_dive_scene.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/resident_memory.hpp"
#include "scanner/common/temporary_folder.hpp"

// The bench runs uwscan's own commands as a user would (simulate, bag export, ros inspect,
// fake-camera, inspect), each a child process whose CPU time and peak memory wait4 reports, beside
// roscore and rosbag play, all inside a private network namespace.
namespace uwscan::app {
namespace {

namespace fs = std::filesystem;

struct RosBenchArgs {
  std::string json;
  std::string scene;  // empty: scenes/inspection_short.yaml in DataFolder()
  std::vector<double> rates = {1.0, 3.39,
                               20.0};  // rosbag play's rates (the dive runs at 100 frames/s)
  double inspect_seconds = 20.0;
  double camera_fps = 339.0;
  // > 0: a soak instead: the long-dive bench's manifold field flown for this many minutes,
  // replayed once at the dive's own rate, figures minute by minute, no peers.
  double long_minutes = 0.0;
};

// Figures of one replay through the node.
struct NodeFigures {
  double rate = 0.0;
  std::int64_t frames_in_bag = 0;
  std::int64_t frames_received = 0, frames_logged = 0, frames_mapped = 0, frames_skipped = 0;
  double frames_per_s = 0.0;  // received over the span from the first to the last
  double cpu_s = 0.0;
  std::int64_t peak_rss_bytes = 0;
  double sweep_latency_median_s = 0.0, sweep_latency_p95_s = 0.0;
  double receive_to_map_median_s = 0.0;
  std::vector<std::pair<double, std::int64_t>> rss;  // (seconds since the node started, bytes)
  nlohmann::json sweep_latency_by_minute;            // as the node wrote it
};

// A process's resident memory, sampled every half second on a thread of its own.
class RssSampler {
 public:
  explicit RssSampler(pid_t pid) : pid_(pid), thread_([this] { Run(); }) {}
  ~RssSampler() { Stop(); }
  RssSampler(const RssSampler&) = delete;
  RssSampler& operator=(const RssSampler&) = delete;
  std::vector<std::pair<double, std::int64_t>> Stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    return samples_;
  }

 private:
  void Run() {
    const auto start = std::chrono::steady_clock::now();
    while (!stop_) {
      if (const std::optional<std::int64_t> bytes = ResidentBytes(pid_)) {
        const double t =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        samples_.emplace_back(t, *bytes);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }

  pid_t pid_;
  std::atomic<bool> stop_{false};
  std::vector<std::pair<double, std::int64_t>> samples_;
  std::thread thread_;
};

std::string Self() { return fs::read_symlink("/proc/self/exe").string(); }

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": not written");
  return nlohmann::json::parse(in);
}

// What a command prints on stdout, with popen (short commands only).
std::string Output(const std::string& command) {
  FILE* pipe = ::popen((command + " 2>/dev/null").c_str(), "r");
  if (pipe == nullptr) return "";
  std::string out;
  std::array<char, 4096> buffer{};
  while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe))
    out.append(buffer.data(), n);
  ::pclose(pipe);
  return out;
}

bool MasterAnswers() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(11311);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool up = ::connect(s, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0;
  ::close(s);
  return up;
}

// Polls `ready` every 200 ms for up to `seconds`; throws naming `what` when it never holds.
template <typename Ready>
void WaitFor(Ready ready, double seconds, const std::string& what) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!ready()) {
    if (std::chrono::steady_clock::now() > deadline)
      throw Error("bench ros: " + what + " within " + std::to_string(seconds) + " s");
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

void EnterPrivateNetwork() {
  if (::unshare(CLONE_NEWNET) != 0) {
    throw Error(
        "bench ros: needs a private network namespace (root): ROS 1 nodes listen on every "
        "interface");
  }
  if (std::system("ip link set lo up") != 0)
    throw Error("bench ros: cannot bring lo up in the private namespace");
}

void SetRosEnvironment(const fs::path& folder) {
  ::setenv("ROS_MASTER_URI", "http://127.0.0.1:11311", 1);
  ::setenv("ROS_IP", "127.0.0.1", 1);
  ::setenv("ROS_HOME", (folder / "ros").c_str(), 1);
  ::setenv("ROS_LOG_DIR", (folder / "ros" / "log").c_str(), 1);
  fs::create_directories(folder / "ros" / "log");
}

NodeFigures ReplayThroughNode(const fs::path& bag, std::int64_t frames_in_bag, double rate,
                              double timeout_s, const fs::path& folder) {
  const std::string name = "node_" + std::to_string(static_cast<int>(rate * 100));
  const fs::path json = folder / (name + ".json"), log = folder / (name + ".log");
  ChildProcess node({Self(), "ros", "inspect", "--log", (folder / (name + ".db")).string(),
                     "--json", json.string(), "--idle-stop-s", "2"},
                    log);
  WaitFor(
      [] {
        return Output("rostopic info /uwscan/frames").find("uwscan_inspection") !=
               std::string::npos;
      },
      30, "the node did not subscribe (see " + log.string() + ")");
  RssSampler memory(node.pid());
  // -d: rosbag play waits after advertising, so that the node has connected before the first frame.
  RunToEnd({"rosbag", "play", "--quiet", "-d", "1", "-r", std::to_string(rate), bag.string()},
           folder / "play.log", timeout_s);
  const std::vector<std::pair<double, std::int64_t>> rss = memory.Stop();
  const ChildProcess::Exit exit = node.Wait(timeout_s);
  if (exit.exit_code != 0) throw Error("bench ros: the node failed (see " + log.string() + ")");
  const nlohmann::json r = ReadJson(json);
  NodeFigures f;
  f.rate = rate;
  f.frames_in_bag = frames_in_bag;
  f.frames_received = r["frames_received"];
  f.frames_logged = r["frames_logged"];
  f.frames_mapped = r["frames_mapped"];
  f.frames_skipped = r["frames_skipped"];
  const double span_s = r["receive_span_s"];
  f.frames_per_s = span_s > 0 ? static_cast<double>(f.frames_received - 1) / span_s : 0.0;
  f.cpu_s = exit.cpu_s;
  f.peak_rss_bytes = exit.max_rss_bytes;
  f.sweep_latency_median_s = r["sweep_latency_s"]["median"];
  f.sweep_latency_p95_s = r["sweep_latency_s"]["p95"];
  f.receive_to_map_median_s = r["receive_to_map_s"]["median"];
  f.rss = rss;
  f.sweep_latency_by_minute = r["sweep_latency_by_minute"];
  return f;
}

struct InspectFigures {
  std::int64_t frames = 0, lost_frames = 0;
  double frames_per_s = 0.0, cpu_s = 0.0;
};

// `inspect` on the fake camera serving the same scene's frames as profiles.
InspectFigures DirectInspect(const RosBenchArgs& a, const fs::path& folder) {
  ChildProcess camera(
      {Self(), "fake-camera", a.scene, "--mode", "profile", "--fps", std::to_string(a.camera_fps)},
      folder / "camera.log");
  // The camera simulates the whole dive before it serves (minutes for a long one).
  WaitFor(
      [&folder] {
        std::ifstream log(folder / "camera.log");
        const std::string text((std::istreambuf_iterator<char>(log)),
                               std::istreambuf_iterator<char>());
        return text.find("fake-camera: serving") != std::string::npos;
      },
      1800, "the fake camera did not start serving (see " + (folder / "camera.log").string() + ")");
  const fs::path json = folder / "inspect.json";
  ChildProcess inspect({Self(), "inspect", "--camera", "127.0.0.1", "--scene", a.scene, "--log",
                        (folder / "inspect.db").string(), "--json", json.string(), "--seconds",
                        std::to_string(a.inspect_seconds)},
                       folder / "inspect.log");
  const ChildProcess::Exit exit = inspect.Wait(a.inspect_seconds + 120);
  if (exit.exit_code != 0)
    throw Error("bench ros: inspect failed (see " + (folder / "inspect.log").string() + ")");
  const nlohmann::json r = ReadJson(json);
  return {.frames = r["frames_received"],
          .lost_frames = r["lost_frames"],
          .frames_per_s = r["frames_per_s"],
          .cpu_s = exit.cpu_s};
}

// CPU seconds per frame of `uwscan map` on the dive: the same SLAM offline, without ROS, camera
// or log writing (its tables already cached by the runs before).
double OfflineMapCpuPerFrame(const fs::path& dive, std::int64_t frames, const fs::path& folder) {
  ChildProcess map({Self(), "map", dive.string(), "-o", (folder / "map.ply").string()},
                   folder / "map.log");
  const ChildProcess::Exit exit = map.Wait(600);
  if (exit.exit_code != 0)
    throw Error("bench ros: map failed (see " + (folder / "map.log").string() + ")");
  return exit.cpu_s / static_cast<double>(std::max<std::int64_t>(1, frames));
}

// Resident memory while the bag played: at a quarter of the replay and at its end (the mapper
// and its queues settled in, then all of the dive), the growth between them per minute of dive
// (replay seconds times the rate), and every sample.
nlohmann::json MemoryJson(const NodeFigures& f) {
  if (f.rss.size() < 4) return nullptr;
  const std::pair<double, std::int64_t>& quarter = f.rss[f.rss.size() / 4];
  const std::pair<double, std::int64_t>& end = f.rss.back();
  const double dive_minutes = (end.first - quarter.first) * f.rate / 60.0;
  nlohmann::json samples = nlohmann::json::array();
  for (const auto& [t, bytes] : f.rss) samples.push_back({t, bytes});
  return {
      {"rss_at_quarter_bytes", quarter.second},
      {"rss_at_end_bytes", end.second},
      {"growth_bytes_per_dive_minute",
       dive_minutes > 0 ? static_cast<double>(end.second - quarter.second) / dive_minutes : 0.0},
      {"samples_s_bytes", samples}};
}

nlohmann::json NodeJson(const NodeFigures& f) {
  return {{"rate", f.rate},
          {"frames_per_s", f.frames_per_s},
          {"lost_frames", f.frames_in_bag - f.frames_received},
          {"frames_skipped_by_mapper", f.frames_skipped},
          {"latency_s", {{"median", f.sweep_latency_median_s}, {"p95", f.sweep_latency_p95_s}}},
          {"receive_to_map_median_s", f.receive_to_map_median_s},
          {"cpu_s_per_frame",
           f.frames_received > 0 ? f.cpu_s / static_cast<double>(f.frames_received) : 0.0},
          {"peak_rss_bytes", f.peak_rss_bytes},
          {"memory", MemoryJson(f)}};
}

// The soak's figures minute by minute of the replay: the node's resident memory at each minute's
// end (its last sample in the minute) and its sweeps' latencies in the minute.
nlohmann::json SoakJson(const NodeFigures& f, double minutes) {
  nlohmann::json per_minute = nlohmann::json::array();
  const nlohmann::json& latency = f.sweep_latency_by_minute;
  std::size_t sample = 0;
  std::int64_t rss_bytes = 0;  // a minute without a sample keeps the one before
  for (std::size_t m = 0; sample < f.rss.size() || m < latency.size(); ++m) {
    while (sample < f.rss.size() && f.rss[sample].first < 60.0 * static_cast<double>(m + 1))
      rss_bytes = f.rss[sample++].second;
    nlohmann::json minute = {
        {"rss_bytes", rss_bytes}, {"sweeps", 0}, {"latency_p95_s", 0.0}, {"latency_max_s", 0.0}};
    if (m < latency.size()) {
      minute["sweeps"] = latency[m]["sweeps"];
      minute["latency_p95_s"] = latency[m]["p95_s"];
      minute["latency_max_s"] = latency[m]["max_s"];
    }
    per_minute.push_back(minute);
  }
  if (per_minute.empty()) throw Error("bench ros: the soak measured no minute");
  // The last minute is the replay's tail and the node's finish, partial: the one before it is the
  // dive's last whole minute. (Memory minutes count from the node's start, latency minutes from
  // its first sweep, a second or two later.)
  const nlohmann::json& last =
      per_minute.size() >= 2 ? per_minute[per_minute.size() - 2] : per_minute.back();
  return {{"minutes", minutes},
          {"frames_lost", f.frames_in_bag - f.frames_received},
          {"frames_skipped_by_mapper", f.frames_skipped},
          {"rss_bytes",
           {{"first_minute", per_minute.front()["rss_bytes"]}, {"last_minute", last["rss_bytes"]}}},
          {"latency_p95_s",
           {{"first_minute", per_minute.front()["latency_p95_s"]},
            {"last_minute", last["latency_p95_s"]}}},
          {"latency_measured", "a sweep's last frame arriving at the node to its PointCloud2"},
          {"per_minute", per_minute}};
}

void PrintSoak(const nlohmann::json& soak) {
  int minute = 0;
  for (const nlohmann::json& m : soak["per_minute"]) {
    std::printf("minute %3d: %4lld sweeps, latency p95 %7.1f ms (max %7.1f), %.0f MB resident\n",
                ++minute, static_cast<long long>(m["sweeps"].get<std::int64_t>()),
                m["latency_p95_s"].get<double>() * 1e3, m["latency_max_s"].get<double>() * 1e3,
                static_cast<double>(m["rss_bytes"].get<std::int64_t>()) * 1e-6);
  }
}

// The long-dive bench's scene of `minutes`, written into `folder` with the scanner file named by
// its absolute path.
fs::path WriteLongDiveScene(double minutes, const fs::path& folder) {
  const fs::path scene = folder / "long_dive.yaml";
  WriteFileAtomically(
      scene, bench::LongDiveSceneYaml(60.0 * minutes, bench::LongDiveBenchOptions{}.seed,
                                      (DataFolder() / "scanners" / "galvo_binned.yaml").string()));
  return scene;
}

// The dive simulated into a log and exported as a bag, and how many frames the bag holds.
struct DiveBag {
  fs::path dive, bag;
  std::int64_t frames = 0;
};

DiveBag SimulateAndExport(const std::string& scene, const fs::path& folder, double timeout_s) {
  DiveBag d{folder / "dive.db", folder / "dive.bag"};
  RunToEnd({Self(), "simulate", scene, "-o", d.dive.string()}, folder / "simulate.log", timeout_s);
  RunToEnd({Self(), "bag", "export", d.dive.string(), "-o", d.bag.string()}, folder / "export.log",
           timeout_s);
  std::ifstream export_log(folder / "export.log");
  const std::string exported((std::istreambuf_iterator<char>(export_log)),
                             std::istreambuf_iterator<char>());
  d.frames = std::stoll(exported.substr(exported.find("bag export: ") + 12));
  return d;
}

void PrintRun(const NodeFigures& f) {
  std::printf(
      "bench ros: rate %.2f: %.0f frames/s through the node, %lld lost, sweep latency median "
      "%.1f ms (p95 %.1f), %.1f us CPU per frame, peak RSS %.0f MB, RSS %.0f -> %.0f MB from a "
      "quarter of the replay to its end\n",
      f.rate, f.frames_per_s, static_cast<long long>(f.frames_in_bag - f.frames_received),
      f.sweep_latency_median_s * 1e3, f.sweep_latency_p95_s * 1e3,
      f.cpu_s / static_cast<double>(std::max<std::int64_t>(1, f.frames_received)) * 1e6,
      static_cast<double>(f.peak_rss_bytes) * 1e-6,
      f.rss.empty() ? 0.0 : static_cast<double>(f.rss[f.rss.size() / 4].second) * 1e-6,
      f.rss.empty() ? 0.0 : static_cast<double>(f.rss.back().second) * 1e-6);
}

// The node's runs beside inspect on the fake camera and map offline: the JSON's figures.
nlohmann::json WithPeers(const std::vector<NodeFigures>& runs, const RosBenchArgs& a,
                         const DiveBag& d, const fs::path& folder) {
  const InspectFigures direct = DirectInspect(a, folder);
  const double inspect_cpu =
      direct.cpu_s / static_cast<double>(std::max<std::int64_t>(1, direct.frames));
  std::printf(
      "bench ros: inspect on the fake camera at %.0f frames/s: %.0f frames/s, %lld lost, %.1f us "
      "CPU per frame\n",
      a.camera_fps, direct.frames_per_s, static_cast<long long>(direct.lost_frames),
      inspect_cpu * 1e6);
  // The headline: the run nearest the seed camera's 339 frames/s (3.39x the dive's 100).
  const NodeFigures* headline = &runs.front();
  for (const NodeFigures& f : runs) {
    if (std::abs(f.rate - 3.39) < std::abs(headline->rate - 3.39)) headline = &f;
  }
  nlohmann::json node = NodeJson(*headline);
  node["runs"] = nlohmann::json::array();
  for (const NodeFigures& f : runs) node["runs"].push_back(NodeJson(f));
  const double node_cpu = node["cpu_s_per_frame"];
  const double overhead = inspect_cpu > 0 ? node_cpu / inspect_cpu - 1.0 : 0.0;
  const double map_cpu = OfflineMapCpuPerFrame(d.dive, d.frames, folder);
  const double overhead_vs_map = map_cpu > 0 ? node_cpu / map_cpu - 1.0 : 0.0;
  std::printf(
      "bench ros: overhead against inspect %.2f, against map offline %.2f (CPU per frame, node / "
      "peer - 1)\n",
      overhead, overhead_vs_map);
  return {{"scene", a.scene},
          {"node", node},
          {"direct_inspect",
           {{"frames_per_s", direct.frames_per_s},
            {"lost_frames", direct.lost_frames},
            {"cpu_s_per_frame", inspect_cpu},
            {"camera_fps", a.camera_fps}}},
          {"offline_map", {{"cpu_s_per_frame", map_cpu}}},
          {"overhead_ratio", overhead},
          {"overhead_vs_map_ratio", overhead_vs_map}};
}

nlohmann::json Soak(const NodeFigures& run, double minutes) {
  const nlohmann::json figures = SoakJson(run, minutes);
  PrintSoak(figures);
  return {
      {"scene", "bench slam --long's manifold field"}, {"node", NodeJson(run)}, {"soak", figures}};
}

void RunRosBench(RosBenchArgs a) {
  if (!a.json.empty()) CheckOutputPath(a.json, "--json");
  if (a.scene.empty()) a.scene = (DataFolder() / "scenes" / "inspection_short.yaml").string();
  EnterPrivateNetwork();
  const fs::path folder = TemporaryFolder() / ("uwscan_bench_ros_" + std::to_string(::getpid()));
  fs::create_directories(folder);
  SetRosEnvironment(folder);
  const bool soak = a.long_minutes > 0.0;
  if (soak) {
    a.scene = WriteLongDiveScene(a.long_minutes, folder).string();
    a.rates = {1.0};
  }
  // Simulating, exporting and replaying a dive of hours takes about as long as the dive; the
  // node's finish (the last whole solve, the map) a few minutes. Other scenes: an hour.
  const double step_timeout_s = soak ? 600.0 + 90.0 * a.long_minutes : 3600.0;
  const DiveBag d = SimulateAndExport(a.scene, folder, step_timeout_s);
  ChildProcess master({"roscore", "-p", "11311"}, folder / "roscore.log");
  WaitFor(MasterAnswers, 30, "roscore did not answer");
  std::this_thread::sleep_for(std::chrono::seconds(1));
  std::vector<NodeFigures> runs;
  for (double rate : a.rates) {
    runs.push_back(ReplayThroughNode(d.bag, d.frames, rate, step_timeout_s, folder));
    PrintRun(runs.back());
  }
  const nlohmann::json figures =
      soak ? Soak(runs.front(), a.long_minutes) : WithPeers(runs, a, d, folder);
  master.Interrupt();
  master.Wait(30);
  fs::remove_all(folder);
  if (!a.json.empty()) WriteJsonFile(a.json, figures);
}

}  // namespace

void AddRosBenchCommand(CLI::App& bench) {
  auto a = std::make_shared<RosBenchArgs>();
  CLI::App* cmd = bench.add_subcommand("ros",
                                       "the ROS node end to end (rosbag play of a simulated dive "
                                       "at several rates) against inspect on the fake "
                                       "camera: frames per second, lost frames, sweep latency, CPU "
                                       "per frame, peak memory (root: private network)");
  cmd->add_option("--json", a->json, "figures as JSON");
  cmd->add_option("--scene", a->scene,
                  "the dive (default: scenes/inspection_short.yaml in the data folder)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--rates", a->rates, "rosbag play rates (the dive's own frame rate times these)")
      ->capture_default_str();
  cmd->add_option("--inspect-seconds", a->inspect_seconds, "how long inspect reads the fake camera")
      ->capture_default_str();
  cmd->add_option("--camera-fps", a->camera_fps, "the fake camera's frame rate (profile mode)")
      ->capture_default_str();
  cmd->add_option("--long-minutes", a->long_minutes,
                  "a soak instead: bench slam --long's manifold field flown this many minutes, "
                  "replayed once at its own rate; memory and latency minute by minute, no peers")
      ->check(CLI::Range(1.0, 600.0))
      ->excludes("--scene")
      ->excludes("--rates");
  cmd->callback([a] { RunRosBench(*a); });
}

}  // namespace uwscan::app
