#include "apps/bench/robustness_bench_command.hpp"

#include <cstdio>
#include <string>

#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/robustness/reader_seeds.hpp"
#include "bench/robustness/robustness_benchmark.hpp"
#include "bench/scratch_folder.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::app {
namespace {

struct RobustnessArgs {
  std::string json;
  std::string write_seeds;
  std::string data;  // empty: DataFolder()
  bench::RobustnessOptions options;
};

void Run(RobustnessArgs a) {
  a.options.data_dir = DataFolderOr(a.data);
  if (!a.write_seeds.empty()) {
    bench::WriteReaderSeeds(a.options.data_dir, a.write_seeds);
    std::printf("seeds written to %s\n", a.write_seeds.c_str());
    return;
  }
  if (!a.json.empty()) CheckOutputPath(a.json, "--json");
  const bench::ScratchFolder scratch("robustness");
  bench::RobustnessResult result;
  {
    ProgressBar progress;
    result = bench::RunRobustnessBenchmark(a.options, scratch.path(), progress.Callback());
  }
  std::printf("%-24s %6s %11s %8s %6s %5s %6s\n", "reader", "tried", "clean_error", "accepted",
              "crash", "hang", "noisy");
  nlohmann::json readers = nlohmann::json::object();
  int failures = 0;
  for (const auto& [name, o] : result.readers) {
    std::printf("%-24s %6d %11d %8d %6d %5d %6d\n", name.c_str(), o.tried, o.clean_error,
                o.accepted, o.crash, o.hang, o.noisy);
    if (!o.first_failure.empty())
      std::printf("  first crash or hang: %s\n", o.first_failure.c_str());
    failures += o.crash + o.hang;
    readers[name] = {{"tried", o.tried},       {"clean_error", o.clean_error},
                     {"accepted", o.accepted}, {"crash", o.crash},
                     {"hang", o.hang},         {"noisy", o.noisy}};
  }
  std::printf(
      "dive logs, %d bytes changed at random, %d trials: %d of %d damaged rows detected "
      "(schema 2, no checksums: %d of %d)\n",
      a.options.damaged_bytes, a.options.dive_log_trials, result.dive_log.detected,
      result.dive_log.damaged_rows, result.dive_log_without_checksums.detected,
      result.dive_log_without_checksums.damaged_rows);
  std::printf("%.1f s\n", result.seconds);
  if (!a.json.empty()) {
    nlohmann::json json = {
        {"readers", readers},
        {"dive_log",
         {{"damaged_rows", result.dive_log.damaged_rows}, {"detected", result.dive_log.detected}}},
        {"dive_log_without_checksums",
         {{"damaged_rows", result.dive_log_without_checksums.damaged_rows},
          {"detected", result.dive_log_without_checksums.detected}}},
        {"mutants_per_kind", a.options.mutants_per_kind},
        {"dive_log_trials", a.options.dive_log_trials},
        {"damaged_bytes", a.options.damaged_bytes},
        {"seed", a.options.seed},
        {"seconds", result.seconds}};
    WriteJsonFile(a.json, json);
  }
  if (failures > 0)
    throw Error("bench robustness: " + std::to_string(failures) + " crashes or hangs");
}

}  // namespace

void AddRobustnessBenchCommand(CLI::App& bench) {
  auto args = std::make_shared<RobustnessArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "robustness",
      "feed every reader mutated files (truncated, bytes flipped, counts inflated, NaN/Inf, "
      "wrong types) and damage dive logs; exits 1 on any crash or hang");
  cmd->add_option("--json", args->json, "write the outcomes as JSON");
  cmd->add_option("--mutants", args->options.mutants_per_kind,
                  "mutants per seed file and kind of mutation")
      ->check(kPositiveNumber);
  cmd->add_option("--trials", args->options.dive_log_trials, "damaged dive logs")
      ->check(kNonNegativeNumber);
  cmd->add_option("--damaged-bytes", args->options.damaged_bytes,
                  "random bytes changed per dive log")
      ->check(kPositiveNumber);
  cmd->add_option("--timeout", args->options.timeout_s,
                  "seconds after which a read counts as a hang")
      ->check(kPositiveNumber);
  cmd->add_option("--seed", args->options.seed, "random seed of the mutations");
  cmd->add_option("--data", args->data,
                  "the data folder (scenes/, scanners/; default: `uwscan --data-dir`)");
  cmd->add_option("--write-seeds", args->write_seeds,
                  "only write the seed files into this folder and stop");
  cmd->callback([args] { Run(*args); });
}

}  // namespace uwscan::app
