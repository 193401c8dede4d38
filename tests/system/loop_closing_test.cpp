// Loop closing end to end on rendered scenes with Kinect-like noise and exact ground truth
// (docs/LOOP.md "Measurements" has the full-length numbers from `plumb run`).
//   - synth:loop, shortened to two 8 s laps (the full preset is two 20 s laps, ~80 s to run twice
//     here): loops are found and the optimised trajectory's ATE is at most half of the ATE
//     without loop closing;
//   - synth:repeated at its full length (900 frames: identical corridor modules, no real loop):
//     no loop accepted;
#include <gtest/gtest.h>

#include "tests/support/odometry_run.h"

namespace plumb::test {
namespace {

SynthOptions shortLoop() {
  SynthOptions o = noisySynth("loop", 480);
  o.loop_period_s = 8.0;  // 240 frames per lap
  return o;
}

OdometryRun runScene(const SynthOptions& options, bool loops, std::vector<StampedPose>* gt) {
  std::unique_ptr<SyntheticSource> source;
  EXPECT_TRUE(SyntheticSource::create(options, &source).ok());
  if (gt != nullptr) *gt = groundTruth(source->scene(), options.frames);
  RunSettings settings;
  settings.loop_closing = loops;
  return runOdometry(*source, systemOptions(true), settings);
}

TEST(LoopClosing, SynthLoopOptimisedAteAtMostHalfOfNoLoopClosing) {
  std::vector<StampedPose> gt;
  const OdometryRun without = runScene(shortLoop(), false, &gt);
  const OdometryRun with = runScene(shortLoop(), true, nullptr);
  ASSERT_TRUE(without.status.ok() && with.status.ok());
  EXPECT_FALSE(without.result.loop.enabled);
  ASSERT_TRUE(with.result.loop.enabled);
  const loop::LoopStats& s = with.result.loop.stats;
  EXPECT_GE(s.loops_accepted, 1u);
  EXPECT_GE(with.stats.loop_corrections_applied, 1u);
  EXPECT_EQ(s.rejected[int(loop::LoopRejection::kImplausible)], 0u);
  const double ate_without = ateRmse(gt, without.trajectory);
  const double ate_realtime = ateRmse(gt, with.trajectory);
  const double ate_optimised = ateRmse(gt, with.optimized);
  std::printf("ATE without loop closing %.4f m; with: real-time %.4f m, optimised %.4f m; loops %llu\n",
              ate_without, ate_realtime, ate_optimised, (unsigned long long)s.loops_accepted);
  EXPECT_LE(ate_optimised, 0.5 * ate_without);
  EXPECT_LE(ate_realtime, ate_without);
  EXPECT_LE(with.result.loop.stats.peak_graph_nodes, with.result.loop.capacity);
}

TEST(LoopClosing, RepeatedCorridorAcceptsNoLoop) {
  const OdometryRun run = runScene(noisySynth("repeated", presetDefaultFrames("repeated")), true, nullptr);
  ASSERT_TRUE(run.status.ok());
  const loop::LoopStats& s = run.result.loop.stats;
  std::printf("repeated corridor: queries %llu, verifications %llu, rejected as implausible %llu\n",
              (unsigned long long)s.queries, (unsigned long long)s.verifications,
              (unsigned long long)s.rejected[int(loop::LoopRejection::kImplausible)]);
  EXPECT_GT(s.queries, 0u);
  EXPECT_EQ(s.loops_accepted, 0u);
  EXPECT_EQ(run.stats.loop_corrections_applied, 0u);
}

}  // namespace
}  // namespace plumb::test
