// Replay pacing on a virtual clock: frames are due at their recorded intervals / speed, gaps are
// clamped, a late consumer restarts the schedule, speed 0 never sleeps.
#include <gtest/gtest.h>

#include "drivers/recording/paced_source.h"
#include "tests/drivers/device_test_util.h"

namespace plumb {
namespace {

std::unique_ptr<FrameSource> framesAt(const std::vector<double>& timestamps) {
  std::vector<RgbdImage> frames = test::makeNoiseFrames(1, 4, 4, static_cast<int>(timestamps.size()));
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i].timestamp_s = timestamps[i];
  return std::make_unique<test::VectorSource>(std::move(frames), test::smallCamera(4, 4));
}

std::vector<int64_t> deliveryTimes(PacedSource& paced, VirtualClock& clock,
                                   int64_t consumer_work_ns = 0) {
  std::vector<int64_t> times;
  RgbdImage out;
  while (paced.next(out) == SourceResult::kFrame) {
    EXPECT_EQ(out.t_sensor_ns, clock.nowNs());
    times.push_back(out.t_sensor_ns);
    clock.advance(consumer_work_ns);
  }
  return times;
}

TEST(PacedSource, DeliversAtTheRecordedRate) {
  VirtualClock clock(1'000'000'000);
  PacedSource paced(framesAt({100.0, 100.0333, 100.0666, 100.1}), {}, clock);
  const std::vector<int64_t> t = deliveryTimes(paced, clock);
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0], 1'000'000'000);
  EXPECT_NEAR(t[1] - t[0], 33'300'000, 1000);
  EXPECT_NEAR(t[2] - t[0], 66'600'000, 1000);
  EXPECT_NEAR(t[3] - t[0], 100'000'000, 1000);
  EXPECT_EQ(paced.stats().late_frames, 0u);
}

TEST(PacedSource, SpeedScalesTheIntervals) {
  VirtualClock clock;
  PacedSourceOptions options;
  options.speed = 2.0;
  PacedSource paced(framesAt({0.0, 0.1, 0.2}), options, clock);
  const std::vector<int64_t> t = deliveryTimes(paced, clock);
  EXPECT_NEAR(t[2] - t[0], 100'000'000, 1000);
}

TEST(PacedSource, LongGapsAreClampedAndBackwardsJumpsDoNotWait) {
  VirtualClock clock;
  PacedSourceOptions options;
  options.max_gap_s = 0.5;
  PacedSource paced(framesAt({0.0, 10.0, 9.0, 9.1}), options, clock);
  const std::vector<int64_t> t = deliveryTimes(paced, clock);
  EXPECT_NEAR(t[1] - t[0], 500'000'000, 1000);
  EXPECT_EQ(t[2], t[1]);
  EXPECT_NEAR(t[3] - t[2], 100'000'000, 1000);
  EXPECT_EQ(paced.stats().clamped_gaps, 2u);
}

TEST(PacedSource, ALateConsumerRestartsTheScheduleWithoutABurst) {
  VirtualClock clock;
  PacedSource paced(framesAt({0.0, 0.1, 0.2, 0.3}), {}, clock);
  const std::vector<int64_t> t = deliveryTimes(paced, clock, /*consumer work*/ 250'000'000);
  // Every frame is late (work 250 ms > interval 100 ms): delivered at once, never sleeping.
  EXPECT_EQ(t, (std::vector<int64_t>{0, 250'000'000, 500'000'000, 750'000'000}));
  EXPECT_EQ(paced.stats().late_frames, 3u);
  EXPECT_EQ(paced.stats().slept_ns, 0);
}

TEST(PacedSource, SpeedZeroIsAsFastAsPossible) {
  VirtualClock clock;
  PacedSourceOptions options;
  options.speed = 0;
  PacedSource paced(framesAt({0.0, 1.0, 2.0}), options, clock);
  deliveryTimes(paced, clock);
  EXPECT_TRUE(clock.sleeps_ns.empty());
  EXPECT_EQ(paced.stats().frames, 3u);
}

}  // namespace
}  // namespace plumb
