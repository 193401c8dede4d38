// Loss, relocalization and a new map segment through the THREADED pipeline (--mode fast): these
// are the frames where the track stage uses the mapper and relocalizer itself, after
// MapperFence::waitForMapper() (pipeline/odometry_system.h). The run must finish (no dead lock),
// account for every frame, and recover as the single-threaded system does
// (tests/system/odometry_recovery_test.cpp).
#include <gtest/gtest.h>

#include "tests/system/odometry_test_util.h"
#include "tools/staged_run.h"

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

struct StagedRun {
  std::vector<StampedPose> trajectory;
  OdometryStats stats;
};

void runFast(FrameSource& source, const SystemOptions& options, StagedRun* run) {
  OdometrySystem system(source.camera(), options);
  auto keep = [run](const FinishedFrame& f) {
    run->trajectory.push_back(StampedPose{f.timestamp_s, f.T_world_cam, f.valid});
  };
  tools::StagedRunOptions staged;
  staged.mode = runtime::RunMode::kFast;
  tools::StagedRunResult result;
  const tools::FrameOutputFn on_output = [&](const FrameOutput&) {
    system.drainFinishedFrames(keep);
    return Status::Ok();
  };
  const Status status = tools::runStaged(source, system, staged, on_output, &result);
  ASSERT_TRUE(status.ok()) << status.message();
  system.finish(keep, [](const RetiredKeyframe&) {});
  run->stats = system.stats();
}

TEST(StagedRecovery, FastModeRelocalizesAfterBlankFrames) {
  constexpr int kBefore = 60, kBlank = 6, kTotal = 110;
  std::unique_ptr<SyntheticScene> scene;
  ASSERT_TRUE(SyntheticScene::create(noisySynth("textured", kTotal), &scene).ok());
  ScriptedSource source(*scene, nullptr, kTotal, kTotal, kBefore, kBefore + kBlank);
  StagedRun run;
  runFast(source, systemOptions(true), &run);
  ASSERT_EQ(run.trajectory.size(), std::size_t(kTotal));
  for (int i = kBefore; i < kBefore + kBlank; ++i) EXPECT_FALSE(run.trajectory[i].valid) << "frame " << i;
  for (int i = kBefore + kBlank; i < kTotal; ++i) EXPECT_TRUE(run.trajectory[i].valid) << "frame " << i;
  EXPECT_EQ(run.stats.frames_lost, uint64_t(kBlank));
  EXPECT_GE(run.stats.relocalizations, 1u);
  EXPECT_EQ(run.stats.segments, 1u);
  EXPECT_LT(ateRmse(groundTruth(*scene, kTotal), run.trajectory), 0.03);
}

TEST(StagedRecovery, FastModeStartsANewSegmentWhenRelocalizationKeepsFailing) {
  constexpr int kFirst = 40, kSecond = 40;
  std::unique_ptr<SyntheticScene> a, b;
  ASSERT_TRUE(SyntheticScene::create(noisySynth("textured", kFirst), &a).ok());
  SynthOptions other = noisySynth("low_texture", kSecond);
  other.seed = 7;
  ASSERT_TRUE(SyntheticScene::create(other, &b).ok());
  ScriptedSource source(*a, b.get(), kFirst, kFirst + kSecond, 0, 0);
  const SystemOptions options = systemOptions(true);
  StagedRun run;
  runFast(source, options, &run);
  EXPECT_EQ(run.trajectory.size(), std::size_t(kFirst + kSecond));
  EXPECT_EQ(run.stats.segments, 2u);
  EXPECT_LE(run.stats.frames_lost, uint64_t(options.odometry.relocalizer.max_lost_frames_before_new_map));
  EXPECT_GT(run.stats.frames_ok, uint64_t(kFirst + kSecond - 15));
}

}  // namespace
}  // namespace plumb::test
