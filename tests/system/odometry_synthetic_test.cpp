// End-to-end odometry on rendered synthetic scenes with Kinect-like noise and exact ground truth.
#include <gtest/gtest.h>

#include "tests/support/odometry_run.h"

namespace plumb::test {
namespace {

constexpr int kSyntheticFrames = 180;

OdometryRun runLowTexture(bool lines, std::vector<StampedPose>* gt) {
  std::unique_ptr<SyntheticSource> source;
  EXPECT_TRUE(SyntheticSource::create(noisySynth("low_texture", kSyntheticFrames), &source).ok());
  *gt = groundTruth(source->scene(), kSyntheticFrames);
  return runOdometry(*source, systemOptions(lines));
}

TEST(OdometrySynthetic, LowTextureEveryFrameTrackedAndAccurate) {
  std::vector<StampedPose> gt;
  const OdometryRun run = runLowTexture(true, &gt);
  ASSERT_EQ(run.trajectory.size(), std::size_t(kSyntheticFrames));
  EXPECT_EQ(run.stats.frames_lost, 0u);
  EXPECT_EQ(run.stats.frames_not_initialized, 0u);
  EXPECT_EQ(run.stats.segments, 1u);
  for (const StampedPose& p : run.trajectory) EXPECT_TRUE(p.valid);
  EXPECT_GE(run.stats.keyframes, 3u);
  EXPECT_LT(ateRmse(gt, run.trajectory), 0.01);
}

// The paper's claim on weak texture: line guidance features make the estimate better.
TEST(OdometrySynthetic, LinesImproveLowTexture) {
  std::vector<StampedPose> gt;
  const double ate_lines = ateRmse(gt, runLowTexture(true, &gt).trajectory);
  const double ate_points = ateRmse(gt, runLowTexture(false, &gt).trajectory);
  EXPECT_LT(ate_lines, ate_points) << "lines " << ate_lines << " m, points only " << ate_points << " m";
}

TEST(OdometrySynthetic, SameInputSameTrajectoryBytes) {
  std::string first, second;
  for (std::string* out : {&first, &second}) {
    std::unique_ptr<SyntheticSource> source;
    ASSERT_TRUE(SyntheticSource::create(noisySynth("textured", 60), &source).ok());
    for (const StampedPose& p : runOdometry(*source, systemOptions(true)).trajectory) *out += formatTumLine(p) + "\n";
  }
  EXPECT_FALSE(first.empty());
  EXPECT_EQ(first, second);
}

}  // namespace
}  // namespace plumb::test
