#pragma once

#include <cstdint>
#include <vector>

// Latencies grouped by the minute in which they were measured: what a soak compares, its first
// minutes against its last (does the node fall behind as the dive grows?).
namespace uwscan::ros {

struct MinuteLatency {
  std::int64_t count = 0;  // latencies measured in the minute (0: none, and the figures are 0)
  double p95_s = 0.0;      // the 95th percentile (nearest rank)
  double max_s = 0.0;
};

class LatencyByMinute {
 public:
  // One latency measured at `at_s` (seconds on any clock; the first call's time starts minute 0).
  // Earlier times than the first count in minute 0.
  void Add(double at_s, double latency_s);
  // Every minute from the first measurement's to the last one's, those without any included.
  std::vector<MinuteLatency> Minutes() const;

 private:
  double first_s_ = 0.0;
  std::vector<std::vector<double>> by_minute_;
};

}  // namespace uwscan::ros
