#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "bench/progress.hpp"

// `uwscan bench robustness`: how every reader of outside data ends on mutated files, each read
// in a child process so that a crash or a hang is counted, not suffered; and how many damaged
// rows of a dive log the checksums give away.
namespace uwscan::bench {

struct RobustnessOptions {
  std::filesystem::path data_dir = "data";  // scenes/ and scanners/ for the seeds
  int mutants_per_kind = 20;                // per seed file and kind of mutation, >= 1
  double timeout_s = 10.0;                  // a read taking longer is a hang, > 0
  int dive_log_trials = 10;                 // dive logs damaged by random bytes, >= 0
  int damaged_bytes = 200;  // random bytes changed in each (the trial), >= 1
  std::uint64_t seed = 1;
  void Check() const;
};

struct ReaderOutcomes {
  int tried = 0;
  int clean_error = 0;        // refused with uwscan::Error
  int accepted = 0;           // read without complaint
  int crash = 0;              // a signal, or an exception that is not uwscan::Error
  int hang = 0;               // still reading after timeout_s
  int noisy = 0;              // wrote to stdout or stderr itself (a clean error must not)
  std::string first_failure;  // the mutation of the first crash or hang, for the report
};

struct DiveLogDamage {
  int damaged_rows =
      0;             // rows (frames, their ground truth, navigation samples) whose content changed
  int detected = 0;  // of those, flagged by the reader instead of handed over
};

struct RobustnessResult {
  std::map<std::string, ReaderOutcomes> readers;
  DiveLogDamage dive_log;                    // schema version 3: per-column checksums
  DiveLogDamage dive_log_without_checksums;  // the same damage in a schema version 2 log
  double seconds = 0.0;
};

// Throws uwscan::Error on invalid options or when the seeds cannot be written in `scratch`.
RobustnessResult RunRobustnessBenchmark(const RobustnessOptions& options,
                                        const std::filesystem::path& scratch,
                                        const Progress& progress = {});

}  // namespace uwscan::bench
