#pragma once

#include <string>
#include <vector>

namespace uwscan::app {

// `uwscan bench slam --long`: mapping cost against dive length (bench/slam/long_dive_benchmark),
// `seeds` dives per length, printed as a table and, when `json` is not empty, written as JSON.
void RunLongDiveBench(const std::vector<double>& minutes, int threads, bool whole_solves, int seeds,
                      const std::string& json);

}  // namespace uwscan::app
