// Monte Carlo NEES in CI (docs/UNCERTAINTY.md): a few seeds of the textured scene with the
// renderer's Kinect-like noise, every published covariance against exact ground truth. The full
// study (50 seeds, scripts/nees_study.sh) gives 0.9-1.05 per dof; a few seeds are noisier, so the
// band here is wider, but it fails for the uncalibrated covariances (checked below) and for a
// calibration that drifts by ~1.7x either way.
#include <gtest/gtest.h>

#include "tests/support/nees_run.h"

namespace plumb::test {
namespace {

constexpr int kNeesFrames = 100;

struct Pooled {
  PooledNees relative, world, motion;
};

Pooled runSeeds(const SystemOptions& options, int seeds, const char* preset = "textured") {
  Pooled p;
  for (int seed = 1; seed <= seeds; ++seed) {
    const NeesRun run = runSyntheticNees(kinectSynth(preset, uint64_t(seed), kNeesFrames), options);
    EXPECT_TRUE(run.status.ok()) << run.status.message();
    EXPECT_EQ(run.frames_with_pose, std::size_t(kNeesFrames)) << "seed " << seed;
    p.relative.add(run.nees.keyframe_relative);
    p.world.add(run.nees.tracked_world);
    p.motion.add(run.nees.frame_motion);
  }
  return p;
}

// Seeds 1-3: per seed the mean NEES/dof varies (0.6-2.4 over 100 frames: a few large frame
// errors dominate a mean), pooled over three it stays within the bands. The uncalibrated model
// (1 px, no variance factor, no scale) on the same runs claims 2-4x the error variance.
TEST(NeesMonteCarlo, CalibratedCovariancesHoldTheirErrorsAndTheModelAsItIsDoesNot) {
  const Pooled p = runSeeds(SystemOptions{}, 3);
  ASSERT_GE(p.relative.count, 8u);  // keyframe pairs with a joint-marginal relative covariance
  ASSERT_GE(p.world.count, std::size_t(3 * (kNeesFrames - 2)));
  std::printf("NEES/dof over 3 seeds: keyframe %.3f (n %zu), tracked %.3f (n %zu), motion %.3f (n %zu)\n",
              p.relative.meanPerDof(), p.relative.count, p.world.meanPerDof(), p.world.count, p.motion.meanPerDof(),
              p.motion.count);
  for (const PooledNees* q : {&p.relative, &p.world, &p.motion}) {
    EXPECT_GT(q->meanPerDof(), 0.6);
    EXPECT_LT(q->meanPerDof(), 2.0);
    EXPECT_GT(q->inside95(), 0.8);
  }

  SystemOptions uncalibrated;
  uncalibrated.odometry.uncertainty.use_variance_factor = false;
  uncalibrated.odometry.uncertainty.relative_scale = 1.0;
  uncalibrated.odometry.uncertainty.tracked_scale = 1.0;
  const Pooled u = runSeeds(uncalibrated, 3);
  std::printf("uncalibrated: keyframe %.3f, tracked %.3f, motion %.3f\n", u.relative.meanPerDof(),
              u.world.meanPerDof(), u.motion.meanPerDof());
  EXPECT_LT(u.relative.meanPerDof(), 0.6);
  EXPECT_LT(u.world.meanPerDof(), 0.6);
  EXPECT_LT(u.motion.meanPerDof(), 0.7);
  EXPECT_GT(p.relative.meanPerDof(), 2.0 * u.relative.meanPerDof());
  EXPECT_GT(p.world.meanPerDof(), 2.0 * u.world.meanPerDof());
  EXPECT_GT(p.motion.meanPerDof(), 2.0 * u.motion.meanPerDof());
}

// The line-rich office (long straight edges): with one pooled variance factor the line samples'
// absorbed residuals pulled the factor down and the keyframe relative covariance was 2-4x
// overconfident (seeds 1-2, 100 frames: NEES/dof 2.8; 10 seeds x 150 frames: 2.40). With the
// variance components (docs/UNCERTAINTY.md) it is 1.10 here (1.25 over 10 seeds x 150 frames).
// The frame motion (MAVLink's velocity) is graded from the previous frame as the current map
// places it: each keyframe's BA moves this office's map by up to ~3 cm between two frames, and
// the published poses' difference made the motion NEES/dof 5.9 on each of these seeds (150 frames,
// with the motion_scale of 1.5 then). Seeds 1-2 are the two highest of ten for the motion (2.54 and
// 1.53 over 150 frames with motion_scale 1.0; the ten pool to 1.22), hence its wider band.
TEST(NeesMonteCarlo, KeyframeCovarianceAndVelocityHoldOnTheLineRichOffice) {
  const Pooled p = runSeeds(SystemOptions{}, 2, "office_loop");
  ASSERT_GE(p.relative.count, 6u);
  std::printf("office_loop NEES/dof over 2 seeds: keyframe %.3f (n %zu), motion %.3f (n %zu)\n", p.relative.meanPerDof(),
              p.relative.count, p.motion.meanPerDof(), p.motion.count);
  EXPECT_GT(p.relative.meanPerDof(), 0.5);
  EXPECT_LT(p.relative.meanPerDof(), 1.8);
  EXPECT_GT(p.motion.meanPerDof(), 0.4);
  EXPECT_LT(p.motion.meanPerDof(), 3.0);
}

}  // namespace
}  // namespace plumb::test
