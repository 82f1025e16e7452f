#include "ros/node/thread_share.hpp"

#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::ros {

ThreadShare::ThreadShare(double share, double min_period_s)
    : share_(share), min_period_s_(min_period_s) {
  if (!(share > 0.0 && share <= 1.0))
    throw Error("ThreadShare: share must be in (0, 1], got " + std::to_string(share));
  if (!(min_period_s >= 0.0))
    throw Error("ThreadShare: min_period_s must be >= 0, got " + std::to_string(min_period_s));
}

bool ThreadShare::Due(double now_s) const {
  if (!last_end_s_) return true;
  const double since_s = now_s - *last_end_s_;
  return since_s >= min_period_s_ && since_s * share_ >= last_cost_s_;
}

void ThreadShare::Done(double start_s, double end_s) {
  last_cost_s_ = end_s - start_s;
  last_end_s_ = end_s;
}

}  // namespace uwscan::ros
