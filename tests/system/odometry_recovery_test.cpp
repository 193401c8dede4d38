// Loss and recovery, in lock-step (deterministic) and through the THREADED pipeline (fast), where
// the track stage relocalizes after MapperFence::waitForMapper() (pipeline/odometry/mapper_fence.h)
// and asks the map stage for a new map: blank frames in the middle of a sequence lose tracking; the
// system marks them lost, relocalizes against its stored keyframes when real frames return, and
// goes on; frames of another scene start a new map segment. Every run must finish (no dead lock)
// and account for every frame, and fast mode must write lock-step's bytes.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tests/support/odometry_run.h"
#include "tests/support/same_trajectory.h"

namespace plumb::test {
namespace {

// Frames of scene `a`, blank frames (sensor covered) in [blank_begin, blank_end), then frames of
// scene `b` (which may be `a` continued).
class ScriptedSource final : public FrameSource {
 public:
  ScriptedSource(const SyntheticScene& a, const SyntheticScene* b, int a_frames, int total, int blank_begin,
                 int blank_end)
      : a_(a), b_(b), a_frames_(a_frames), total_(total), blank_begin_(blank_begin), blank_end_(blank_end) {}

  SourceResult next(RgbdImage& out) override {
    if (next_ >= total_) return SourceResult::kEndOfStream;
    const int i = next_++;
    const bool from_a = b_ == nullptr || i < a_frames_;
    status_ = from_a ? a_.render(i, out) : b_->render(i - a_frames_, out);
    if (!status_.ok()) return SourceResult::kError;
    out.sequence = uint64_t(i);
    out.timestamp_s = 1000.0 + i / 30.0;
    if (i >= blank_begin_ && i < blank_end_) {
      out.bgr.setTo(cv::Scalar::all(0));
      out.depth_raw.setTo(cv::Scalar::all(0));
    }
    return SourceResult::kFrame;
  }
  const PinholeCamera& camera() const override { return a_.camera(); }
  std::string describe() const override { return "scripted synthetic"; }
  const Status& lastError() const override { return status_; }

 private:
  const SyntheticScene& a_;
  const SyntheticScene* b_;
  int a_frames_, total_, blank_begin_, blank_end_;
  int next_ = 0;
  Status status_;
};

class OdometryRecovery : public ::testing::TestWithParam<runtime::RunMode> {
 protected:
  OdometryRun run(FrameSource& source, const SystemOptions& options) {
    RunSettings settings;
    settings.mode = GetParam();
    OdometryRun r = runOdometry(source, options, settings);
    EXPECT_TRUE(r.status.ok()) << r.status.message();
    return r;
  }
  double ateBound() const { return 0.02; }
};

TEST_P(OdometryRecovery, RelocalizesAfterBlankFramesAndMarksThemLost) {
  constexpr int kBefore = 60, kBlank = 6, kTotal = 110;
  std::unique_ptr<SyntheticScene> scene;
  ASSERT_TRUE(SyntheticScene::create(noisySynth("textured", kTotal), &scene).ok());
  ScriptedSource source(*scene, nullptr, kTotal, kTotal, kBefore, kBefore + kBlank);
  const OdometryRun r = run(source, systemOptions(true));
  ASSERT_EQ(r.trajectory.size(), std::size_t(kTotal));
  for (int i = kBefore; i < kBefore + kBlank; ++i) EXPECT_FALSE(r.trajectory[i].valid) << "frame " << i;
  for (int i = kBefore + kBlank; i < kTotal; ++i) EXPECT_TRUE(r.trajectory[i].valid) << "frame " << i;
  EXPECT_EQ(r.stats.frames_lost, uint64_t(kBlank));
  EXPECT_GE(r.stats.relocalizations, 1u);
  EXPECT_EQ(r.stats.segments, 1u);  // relocalized: no new map was needed
  // The relocalized poses continue the same world frame.
  EXPECT_LT(ateRmse(groundTruth(*scene, kTotal), r.trajectory), ateBound());
}

TEST_P(OdometryRecovery, NewMapSegmentWhenRelocalizationKeepsFailing) {
  // Frames of a different scene (another seed) after the first: no stored keyframe matches them,
  // so after M lost frames a new map starts and the trajectory continues.
  constexpr int kFirst = 40, kSecond = 40;
  std::unique_ptr<SyntheticScene> a, b;
  ASSERT_TRUE(SyntheticScene::create(noisySynth("textured", kFirst), &a).ok());
  SynthOptions other = noisySynth("low_texture", kSecond);
  other.seed = 7;
  ASSERT_TRUE(SyntheticScene::create(other, &b).ok());
  ScriptedSource source(*a, b.get(), kFirst, kFirst + kSecond, 0, 0);
  const SystemOptions options = systemOptions(true);
  const OdometryRun r = run(source, options);
  EXPECT_EQ(r.trajectory.size(), std::size_t(kFirst + kSecond));
  EXPECT_EQ(r.stats.segments, 2u);
  EXPECT_LE(r.stats.frames_lost, uint64_t(options.odometry.relocalizer.max_lost_frames_before_new_map));
  EXPECT_GT(r.stats.frames_ok, uint64_t(kFirst + kSecond - 15));
}

// Every phase of the tracking state machine in one sequence (start a map, track, lost after blank
// frames, relocalize, lost in another scene, a new map segment): fast mode, its map stage made slow,
// writes lock-step's bytes. The new maps are built by the map stage from the tracker's request.
TEST(OdometryRecoveryBytes, FastWritesLockStepsBytesThroughLossRelocalizationAndANewSegment) {
  constexpr int kFirst = 80, kBlankBegin = 40, kBlankEnd = 46, kSecond = 40;
  std::unique_ptr<SyntheticScene> a, b;
  ASSERT_TRUE(SyntheticScene::create(noisySynth("textured", kFirst), &a).ok());
  SynthOptions other = noisySynth("low_texture", kSecond);
  other.seed = 7;
  ASSERT_TRUE(SyntheticScene::create(other, &b).ok());
  ScriptedSource lock_step_source(*a, b.get(), kFirst, kFirst + kSecond, kBlankBegin, kBlankEnd);
  const OdometryRun lock_step = runOdometry(lock_step_source, systemOptions(true));
  ASSERT_TRUE(lock_step.status.ok()) << lock_step.status.message();
  ASSERT_GE(lock_step.stats.relocalizations, 1u);
  ASSERT_EQ(lock_step.stats.segments, 2u);

  ScriptedSource fast_source(*a, b.get(), kFirst, kFirst + kSecond, kBlankBegin, kBlankEnd);
  RunSettings slow;
  slow.mode = runtime::RunMode::kFast;
  slow.on_frame = [](const FrameOutput& out) {
    std::this_thread::sleep_for(std::chrono::milliseconds(out.keyframe ? 4 : 1));
  };
  const OdometryRun fast = runOdometry(fast_source, systemOptions(true), slow);
  ASSERT_TRUE(fast.status.ok()) << fast.status.message();
  EXPECT_TRUE(sameTrajectory(fast.trajectory, lock_step.trajectory));
  EXPECT_TRUE(sameTrajectory(fast.optimized, lock_step.optimized));
  EXPECT_EQ(fast.stats.relocalizations, lock_step.stats.relocalizations);
  EXPECT_EQ(fast.stats.segments, lock_step.stats.segments);
}

INSTANTIATE_TEST_SUITE_P(Modes, OdometryRecovery,
                         ::testing::Values(runtime::RunMode::kDeterministic, runtime::RunMode::kFast),
                         [](const ::testing::TestParamInfo<runtime::RunMode>& info) {
                           return std::string(runtime::runModeName(info.param));
                         });

}  // namespace
}  // namespace plumb::test
