#pragma once

#include <optional>

// Work that grows with the dive on a thread that must keep up with it (the newest pose's
// covariance from the whole graph, the whole map): done again only once `share` of the time since
// it was last done would have paid for what it took then. Its share of the thread stays bounded
// however much it costs, and it comes less often as it grows; while it is cheap, it comes every
// `min_period_s` (0: whenever asked).
namespace uwscan::ros {

class ThreadShare {
 public:
  // 0 < share <= 1, min_period_s >= 0 (uwscan::Error otherwise).
  ThreadShare(double share, double min_period_s);
  // Whether the work is due at `now_s` (seconds on a steady clock). The first time: yes.
  bool Due(double now_s) const;
  // The work ran from `start_s` to `end_s`.
  void Done(double start_s, double end_s);

 private:
  double share_, min_period_s_;
  std::optional<double> last_end_s_;
  double last_cost_s_ = 0.0;
};

}  // namespace uwscan::ros
