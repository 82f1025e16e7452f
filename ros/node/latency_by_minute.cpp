#include "ros/node/latency_by_minute.hpp"

#include <algorithm>
#include <cmath>

namespace uwscan::ros {

void LatencyByMinute::Add(double at_s, double latency_s) {
  if (by_minute_.empty()) first_s_ = at_s;
  const double minute = std::floor((at_s - first_s_) / 60.0);
  const auto index = static_cast<std::size_t>(std::max(0.0, minute));
  if (index >= by_minute_.size()) by_minute_.resize(index + 1);
  by_minute_[index].push_back(latency_s);
}

std::vector<MinuteLatency> LatencyByMinute::Minutes() const {
  std::vector<MinuteLatency> minutes;
  minutes.reserve(by_minute_.size());
  for (std::vector<double> latencies : by_minute_) {
    MinuteLatency m;
    m.count = static_cast<std::int64_t>(latencies.size());
    if (!latencies.empty()) {
      std::sort(latencies.begin(), latencies.end());
      const auto rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(m.count)));
      m.p95_s = latencies[rank - 1];
      m.max_s = latencies.back();
    }
    minutes.push_back(m);
  }
  return minutes;
}

}  // namespace uwscan::ros
