#include "ros/node/thread_share.hpp"

#include <gtest/gtest.h>

#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

// A thread asks every 10 ms of a simulated clock; the work costs more as the "dive" goes on.
// Returns the share of the thread's time the work took over [from_s, to_s), and how many times
// it ran there.
struct Spent {
  double share = 0.0;
  int runs = 0;
};
Spent Simulate(ThreadShare& budget, double (*cost_s)(double), double from_s, double to_s) {
  double now_s = 0.0, busy_in_window_s = 0.0;
  int runs = 0;
  while (now_s < to_s) {
    if (budget.Due(now_s)) {
      const double cost = cost_s(now_s);
      budget.Done(now_s, now_s + cost);
      if (now_s >= from_s) {
        busy_in_window_s += cost;
        ++runs;
      }
      now_s += cost;
    }
    now_s += 0.01;
  }
  return {busy_in_window_s / (to_s - from_s), runs};
}

TEST(ThreadShare, CheapWorkComesEveryPeriod) {
  ThreadShare budget(0.1, 2.0);
  const Spent spent = Simulate(
      budget, [](double) { return 0.001; }, 0.0, 600.0);
  EXPECT_NEAR(spent.runs, 300, 3);  // every 2 s (and the 10 ms of asking)
}

TEST(ThreadShare, WorkThatGrowsKeepsItsShare) {
  ThreadShare budget(0.1, 2.0);
  // 10 ms at first, 1.2 s after an hour: alone every 2 s it would take 60 % of the thread.
  const Spent spent = Simulate(
      budget, [](double t_s) { return 0.01 + t_s / 3000.0; }, 3000.0, 3600.0);
  EXPECT_LE(spent.share, 0.1 + 0.005);
  EXPECT_GE(spent.share, 0.1 - 0.02);  // it still comes as often as the share allows
  EXPECT_GT(spent.runs, 40);
}

TEST(ThreadShare, RefusesASharePastTheWholeThread) {
  EXPECT_THROW(ThreadShare(0.0, 1.0), Error);
  EXPECT_THROW(ThreadShare(1.5, 1.0), Error);
  EXPECT_THROW(ThreadShare(0.1, -1.0), Error);
}

}  // namespace
}  // namespace uwscan::ros
