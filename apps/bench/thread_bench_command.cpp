#include "apps/bench/thread_bench_command.hpp"

#include <cstdio>
#include <filesystem>
#include <string>

#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/scratch_folder.hpp"
#include "bench/thread_load_benchmark.hpp"

namespace uwscan::app {
namespace {

struct ThreadBenchArgs {
  std::string json;
  std::string data;  // empty: DataFolder()
  bench::ThreadLoadOptions options;
};

void Run(ThreadBenchArgs a) {
  if (!a.json.empty()) CheckOutputPath(a.json, "--json");
  a.options.uwscan = std::filesystem::read_symlink("/proc/self/exe");
  a.options.data_dir = DataFolderOr(a.data);
  const bench::ScratchFolder scratch("threads");
  bench::ThreadLoadResult result;
  {
    ProgressBar progress;
    result = bench::RunThreadLoadBenchmark(a.options, scratch.path(), progress.Callback());
  }
  std::printf(
      "%d CPUs; median of %d runs, seconds (2 threads / 1 thread: above 1 means the second thread "
      "cost time)\n",
      result.cpus, a.options.repeats);
  std::printf("%-26s %-8s %-7s %8s %8s %8s\n", "workload", "load", "policy", "1 thread",
              "2 threads", "ratio");
  nlohmann::json runs = nlohmann::json::array();
  nlohmann::json ratios = nlohmann::json::object();
  for (const bench::ThreadLoadTiming& t : result.timings) {
    runs.push_back({{"workload", t.workload},
                    {"policy", t.policy},
                    {"loaded", t.loaded},
                    {"threads", t.threads},
                    {"median_s", t.median_s},
                    {"runs_s", t.runs_s}});
    if (t.threads != 2) continue;
    const double one = result.Median(t.workload, t.policy, t.loaded, 1);
    const double ratio = t.median_s / one;
    const char* load = t.loaded ? "loaded" : "idle";
    std::printf("%-26s %-8s %-7s %8.2f %8.2f %8.2f\n", t.workload.c_str(), load, t.policy.c_str(),
                one, t.median_s, ratio);
    ratios[t.workload][load][t.policy] = ratio;
  }
  std::printf("%.0f s\n", result.seconds);
  if (!a.json.empty()) {
    WriteJsonFile(a.json, {{"cpus", result.cpus},
                           {"repeats", a.options.repeats},
                           {"two_over_one_thread", ratios},
                           {"runs", runs},
                           {"seconds", result.seconds}});
  }
}

}  // namespace

void AddThreadBenchCommand(CLI::App& bench) {
  auto args = std::make_shared<ThreadBenchArgs>();
  CLI::App* cmd = bench.add_subcommand("threads",
                                       "time OpenMP commands with 1 and 2 threads, wait policies "
                                       "PASSIVE (uwscan's default) and ACTIVE, "
                                       "idle and with another process busy on the last CPU");
  cmd->add_option("--json", args->json, "write the timings as JSON");
  cmd->add_option("--repeats", args->options.repeats, "runs per configuration (the median is kept)")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--data", args->data, "the data folder (scenes/; default: `uwscan --data-dir`)");
  cmd->callback([args] { Run(*args); });
}

}  // namespace uwscan::app
