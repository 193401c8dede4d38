#include "platform/monotonic_time.h"

#include <gtest/gtest.h>

namespace plumb {
namespace {

TEST(MonotonicTime, NeverDecreases) {
  int64_t previous = monotonicNowNs();
  for (int i = 0; i < 10000; ++i) {
    const int64_t now = monotonicNowNs();
    ASSERT_GE(now, previous);
    previous = now;
  }
}

TEST(MonotonicTime, SleepUntilReachesTheDeadline) {
  const int64_t deadline = monotonicNowNs() + 2'000'000;  // 2 ms
  sleepUntilMonotonicNs(deadline);
  EXPECT_GE(monotonicNowNs(), deadline);
}

TEST(MonotonicTime, SleepUntilThePastReturnsAtOnce) {
  const int64_t start = monotonicNowNs();
  sleepUntilMonotonicNs(start - 1'000'000'000);
  EXPECT_LT(monotonicNowNs() - start, 100'000'000);  // generous: only "did not sleep a second"
}

}  // namespace
}  // namespace plumb
