// Real-time mode on a VirtualClock (pipeline/run/odometry_run.h): the map stage made slow on one frame fills
// every slot, exactly the frames that arrive meanwhile are dropped, and each dropped frame keeps its
// place in the output trajectory as `# <timestamp> dropped`.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/trajectory_io.h"
#include "drivers/common/source_capture.h"
#include "pipeline/run/odometry_run.h"
#include "runtime/clock.h"

namespace plumb {
namespace {

constexpr int kDropFrames = 40;
constexpr int kSlowFrame = 10;
constexpr int64_t kSlowNs = 190'000'000;  // 5.7 frame periods at 30 Hz

struct DropRun {
  std::vector<FinishedFrame> frames;  // the output trajectory, in output order
  OdometryRunResult result;
  std::vector<double> source_timestamps;
};

// Every stage takes no virtual time except the map stage on kSlowFrame (the sink runs inside the
// map stage's step, so advancing the clock there makes that step long).
class SlowOnceSink final : public OdometrySink {
 public:
  SlowOnceSink(runtime::VirtualClock& clock, DropRun* run) : clock_(clock), run_(run) {}
  Status onFrame(const FrameOutput& out) override {
    if (!out.dropped && processed_++ == kSlowFrame) clock_.advanceNs(kSlowNs);
    return Status::Ok();
  }
  Status onFinishedFrame(const FinishedFrame& f) override {
    run_->frames.push_back(f);
    return Status::Ok();
  }

 private:
  runtime::VirtualClock& clock_;
  DropRun* run_;
  int processed_ = 0;
};

void runWithSlowMapStage(DropRun* run) {
  SynthOptions synth;
  synth.preset = "textured";
  synth.frames = kDropFrames;
  std::unique_ptr<SyntheticSource> source;
  ASSERT_TRUE(SyntheticSource::create(synth, &source).ok());
  for (int i = 0; i < kDropFrames; ++i) run->source_timestamps.push_back(source->scene().timestamp(i));

  runtime::VirtualClock clock;
  OdometryRunOptions options;
  options.schedule.mode = runtime::RunMode::kRealtime;
  options.schedule.clock = &clock;
  options.schedule.slot_count = 4;
  SlowOnceSink sink(clock, run);
  SourceCapture capture(*source);
  const Status status = runOdometry(capture, SystemOptions{}, sink, options, &run->result);
  ASSERT_TRUE(status.ok()) << status.message();
}

TEST(StagedDrops, SlowMapStageDropsExactlyTheFramesThatFindNoSlot) {
  DropRun run;
  runWithSlowMapStage(&run);
  // Frame 10 holds the map stage from 333 ms to 523 ms; frames 11..13 fill the other three slots,
  // so 14 (467 ms) and 15 (500 ms) find none; 16 (533 ms) finds the slots freed at 523 ms.
  EXPECT_EQ(run.result.report.frames_dropped, 2u);
  EXPECT_EQ(run.result.report.frames_late, 0u);
  EXPECT_EQ(run.result.report.frames_completed, uint64_t(kDropFrames - 2));
  EXPECT_EQ(run.result.drops_without_trajectory_line, 0u);

  // One output line per source frame, in source order; the dropped ones are exactly 14 and 15.
  ASSERT_EQ(run.frames.size(), std::size_t(kDropFrames));
  for (int i = 0; i < kDropFrames; ++i) {
    EXPECT_DOUBLE_EQ(run.frames[std::size_t(i)].timestamp_s, run.source_timestamps[std::size_t(i)]) << i;
    const bool expect_dropped = i == 14 || i == 15;
    EXPECT_EQ(run.frames[std::size_t(i)].dropped, expect_dropped) << i;
    if (expect_dropped) {
      EXPECT_FALSE(run.frames[std::size_t(i)].valid) << i;
    }
  }
}

TEST(StagedDrops, DroppedFrameIsWrittenAsADroppedComment) {
  StampedPose pose;
  pose.timestamp = 1000.5;
  pose.valid = false;
  pose.dropped = true;
  EXPECT_EQ(formatTumLine(pose), "# 1000.500000 dropped");
  pose.dropped = false;
  EXPECT_EQ(formatTumLine(pose), "# 1000.500000 lost");
}

}  // namespace
}  // namespace plumb
