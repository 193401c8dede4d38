// Unregistered depth through THE runner (pipeline/run/odometry_run.h): a synthetic scene whose depth
// comes from a depth camera 2.5 cm beside the colour camera (SynthOptions::depth_camera).
//   - the run has a `register` stage (report row, trace track), every frame registered;
//   - fast mode writes the deterministic mode's poses with the extra stage too, and allocates
//     nothing per frame after warm-up (registration included);
//   - accuracy: with registration the ATE stays near the registered scene's; the same depth used
//     as if it were registered is clearly worse.
#include <gtest/gtest.h>

#include <cstdio>

#include "drivers/synth/synthetic_scene.h"
#include "tests/support/odometry_run.h"

namespace plumb {
namespace {

constexpr int kFrames = 150;

// A source that hides the depth camera: the offset depth read as if registered.
class AsIfRegistered final : public FrameSource {
 public:
  explicit AsIfRegistered(std::unique_ptr<SyntheticSource> inner) : inner_(std::move(inner)) {
    camera_ = inner_->camera();
    camera_.depth_camera.reset();
  }
  SourceResult next(RgbdImage& out) override { return inner_->next(out); }
  const PinholeCamera& camera() const override { return camera_; }
  std::string describe() const override { return "as-if-registered " + inner_->describe(); }
  const Status& lastError() const override { return inner_->lastError(); }

 private:
  std::unique_ptr<SyntheticSource> inner_;
  PinholeCamera camera_;
};

std::unique_ptr<SyntheticSource> offsetSource(const std::string& preset, bool offset) {
  SynthOptions options = test::noisySynth(preset, kFrames);
  if (offset) options.depth_camera = synthOffsetDepthCamera();
  std::unique_ptr<SyntheticSource> source;
  const Status st = SyntheticSource::create(options, &source);
  EXPECT_TRUE(st.ok()) << st.message();
  return source;
}

const runtime::StageReport* findStage(const runtime::RunReport& report, const std::string& name) {
  for (const runtime::StageReport& s : report.stages)
    if (s.name == name) return &s;
  return nullptr;
}

TEST(RegistrationRun, RegisterStageRunsEveryFrameFastEqualsDeterministicNoAllocations) {
  auto lock_step_source = offsetSource("low_texture", true);
  auto fast_source = offsetSource("low_texture", true);
  ASSERT_TRUE(lock_step_source && fast_source);
  test::RunSettings settings;
  const test::OdometryRun lock_step = test::runOdometry(*lock_step_source, SystemOptions(), settings);
  settings.mode = runtime::RunMode::kFast;
  const test::OdometryRun fast = test::runOdometry(*fast_source, SystemOptions(), settings);
  ASSERT_TRUE(lock_step.status.ok()) << lock_step.status.message();
  ASSERT_TRUE(fast.status.ok()) << fast.status.message();
  for (const test::OdometryRun* run : {&lock_step, &fast}) {
    const runtime::StageReport* reg = findStage(run->result.report, "register");
    ASSERT_NE(reg, nullptr);
    EXPECT_EQ(reg->latency.count(), uint64_t(kFrames));
    // capture, register, extract, track, map; the threaded modes extract even and odd frames apart.
    EXPECT_EQ(run->result.report.stages.size(), run == &fast ? 6u : 5u);
    EXPECT_EQ(run->result.extraction_failures, 0u);
    EXPECT_EQ(run->trajectory.size(), std::size_t(kFrames));
  }
  ASSERT_EQ(lock_step.trajectory.size(), fast.trajectory.size());
  for (std::size_t i = 0; i < fast.trajectory.size(); ++i) {
    ASSERT_EQ(fast.trajectory[i].valid, lock_step.trajectory[i].valid) << i;
    EXPECT_TRUE(fast.trajectory[i].T_world_cam.matrix() == lock_step.trajectory[i].T_world_cam.matrix()) << i;
  }
  EXPECT_GT(fast.result.allocation_frames, 100u);
  EXPECT_EQ(fast.result.allocations_after_warmup, 0u);
}

TEST(RegistrationRun, RegistrationKeepsTheRegisteredAccuracyWithoutItIsWorse) {
  auto registered_source = offsetSource("textured", false);
  auto offset_source = offsetSource("textured", true);
  auto hidden = std::make_unique<AsIfRegistered>(offsetSource("textured", true));
  ASSERT_TRUE(registered_source && offset_source);
  const std::vector<StampedPose> gt = test::groundTruth(registered_source->scene(), kFrames);
  const test::OdometryRun registered = test::runOdometry(*registered_source, SystemOptions());
  const test::OdometryRun with = test::runOdometry(*offset_source, SystemOptions());
  const test::OdometryRun without = test::runOdometry(*hidden, SystemOptions());
  ASSERT_TRUE(registered.status.ok() && with.status.ok() && without.status.ok());
  EXPECT_EQ(findStage(registered.result.report, "register"), nullptr);  // registered: no such stage
  EXPECT_EQ(findStage(without.result.report, "register"), nullptr);
  const double ate_registered = test::ateRmse(gt, registered.trajectory);
  const double ate_with = test::ateRmse(gt, with.trajectory);
  const double ate_without = test::ateRmse(gt, without.trajectory);
  std::printf("textured seed 1, %d frames, Kinect-like noise: ATE registered %.4f m, with registration %.4f m, "
              "without %.4f m\n",
              kFrames, ate_registered, ate_with, ate_without);
  EXPECT_LT(ate_with, std::max(1.5 * ate_registered, ate_registered + 0.003));
  EXPECT_GT(ate_without, 2 * ate_with);
}

}  // namespace
}  // namespace plumb
