// Device-to-host timestamp mapping: latency jitter is rejected, drift is followed, and a device
// clock restart re-anchors the mapping.
#include <gtest/gtest.h>

#include <random>

#include "drivers/openni2/device_clock_mapper.h"

namespace plumb {
namespace {

TEST(DeviceClockMapper, RejectsLatencyJitterAndNeverMapsIntoTheFuture) {
  DeviceClockMapper mapper;
  std::mt19937 rng(3);
  const int64_t host_start = 100'000'000'000, device_start = 5'000'000;
  int64_t worst_error = 0;
  for (int i = 0; i < 300; ++i) {
    const int64_t capture_host = host_start + i * 33'333'333LL;  // true capture time
    const int64_t device = device_start + i * 33'333'333LL;
    const int64_t latency = 2'000'000 + static_cast<int64_t>(rng() % 8'000'000);  // 2-10 ms
    const int64_t mapped = mapper.toHostNs(device, capture_host + latency);
    EXPECT_LE(mapped, capture_host + latency);
    if (i >= 30) worst_error = std::max<int64_t>(worst_error, std::llabs(mapped - capture_host));
  }
  // After a second the estimate sits near the minimum latency (2 ms), not the mean (6 ms):
  // the least-delayed of 64 uniform 2-10 ms latencies is almost always below 2.6 ms.
  EXPECT_LT(worst_error, 2'600'000);
}

TEST(DeviceClockMapper, FollowsSlowDriftAndReanchorsAfterAClockReset) {
  DeviceClockMapper mapper;
  const int64_t latency = 3'000'000;
  int64_t mapped = 0, capture_host = 0;
  for (int i = 0; i < 600; ++i) {  // device clock runs 100 ppm slow
    capture_host = 50'000'000'000 + i * 33'333'333LL;
    const int64_t device = static_cast<int64_t>(i * 33'333'333LL * (1 - 100e-6));
    mapped = mapper.toHostNs(device, capture_host + latency);
  }
  EXPECT_NEAR(static_cast<double>(mapped - capture_host), latency, 250'000);  // window lag
  EXPECT_EQ(mapper.resets(), 0u);
  // Reconnect: the device clock starts again from zero.
  mapped = mapper.toHostNs(1'000, capture_host + 1'000'000'000 + latency);
  EXPECT_EQ(mapper.resets(), 1u);
  EXPECT_EQ(mapped, capture_host + 1'000'000'000 + latency);
}

}  // namespace
}  // namespace plumb
