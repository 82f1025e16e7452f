#pragma once

#include <string>
#include <vector>

namespace uwscan::app {

// `uwscan bench slam --long`: mapping cost against dive length (bench/slam/long_dive_benchmark),
// `seeds` dives per length, printed as a table and, when `json` is not empty, written as JSON;
// whole_solve_lag_s: MapperOptions::whole_solve_lag_s of the windowed mapping.
void RunLongDiveBench(const std::vector<double>& minutes, int threads, bool whole_solves,
                      double whole_solve_lag_s, int seeds, const std::string& json);

}  // namespace uwscan::app
