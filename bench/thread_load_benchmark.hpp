#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "bench/progress.hpp"

namespace uwscan::bench {

// Does adding an OpenMP thread ever cost time? (issue 14, item 6.) With libgomp spinning while
// it waits (OMP_WAIT_POLICY=ACTIVE), a second thread that shares its core with another busy
// process burns that core's time slices waiting at every barrier, and the run can end later than
// with one thread. uwscan runs with OMP_WAIT_POLICY=PASSIVE unless the environment says
// otherwise (apps/main.cpp). This benchmark runs real uwscan commands as child processes with
// 1 and 2 threads, under both wait policies, with the machine idle and with another process
// spinning on the last CPU, and times them (wall clock, median of the repeats).
struct ThreadLoadOptions {
  std::filesystem::path uwscan;    // the uwscan executable the commands run
  std::filesystem::path data_dir;  // the project's data/ folder (scenes)
  int repeats = 3;                 // runs per configuration; the median is kept, >= 1
  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
};

struct ThreadLoadTiming {
  std::string workload;  // e.g. "build-db pipe"
  std::string policy;    // "PASSIVE" (uwscan's default) or "ACTIVE" (spin-waiting)
  bool loaded = false;   // another process spun on the last CPU
  int threads = 1;
  double median_s = 0.0;
  std::vector<double> runs_s;
};

struct ThreadLoadResult {
  std::vector<ThreadLoadTiming> timings;
  int cpus = 0;
  double seconds = 0.0;

  // Median seconds of one configuration; throws uwscan::Error when it was not measured.
  double Median(const std::string& workload, const std::string& policy, bool loaded,
                int threads) const;
};

// Runs the workloads in `scratch` (their outputs are written there). Throws uwscan::Error when a
// command fails.
ThreadLoadResult RunThreadLoadBenchmark(const ThreadLoadOptions& options,
                                        const std::filesystem::path& scratch,
                                        const Progress& progress);

}  // namespace uwscan::bench
