#include "ros/node/latency_by_minute.hpp"

#include <gtest/gtest.h>

namespace uwscan::ros {
namespace {

TEST(LatencyByMinute, GroupsByTheMinuteSinceTheFirstWithEmptyMinutesKept) {
  LatencyByMinute latencies;
  // Minute 0: 1..100 ms (nearest-rank p95: 95 ms); minute 1: none; minute 2: one of 7 ms.
  for (int i = 1; i <= 100; ++i) latencies.Add(1000.0 + 0.5 * i, 1e-3 * i);
  latencies.Add(1000.0 + 125.0, 0.007);
  const std::vector<MinuteLatency> minutes = latencies.Minutes();
  ASSERT_EQ(minutes.size(), 3u);
  EXPECT_EQ(minutes[0].count, 100);
  EXPECT_DOUBLE_EQ(minutes[0].p95_s, 0.095);
  EXPECT_DOUBLE_EQ(minutes[0].max_s, 0.100);
  EXPECT_EQ(minutes[1].count, 0);
  EXPECT_EQ(minutes[1].p95_s, 0.0);
  EXPECT_EQ(minutes[2].count, 1);
  EXPECT_DOUBLE_EQ(minutes[2].p95_s, 0.007);
}

TEST(LatencyByMinute, NothingMeasuredIsNoMinute) {
  EXPECT_TRUE(LatencyByMinute().Minutes().empty());
}

TEST(LatencyByMinute, AClockThatStepsBackCountsInTheFirstMinute) {
  LatencyByMinute latencies;
  latencies.Add(100.0, 0.01);
  latencies.Add(40.0, 0.02);
  const std::vector<MinuteLatency> minutes = latencies.Minutes();
  ASSERT_EQ(minutes.size(), 1u);
  EXPECT_EQ(minutes[0].count, 2);
  EXPECT_DOUBLE_EQ(minutes[0].max_s, 0.02);
}

}  // namespace
}  // namespace uwscan::ros
