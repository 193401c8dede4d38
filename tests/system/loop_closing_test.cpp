// Loop closing end to end on rendered scenes with Kinect-like noise and exact ground truth
// (docs/LOOP.md "Measurements" has the full-length numbers from `plumb run`).
//   - synth:loop, shortened to two 8 s laps (the full preset is two 20 s laps, ~80 s to run twice
//     here): loops are found and the optimised trajectory's ATE is at most half of the ATE
//     without loop closing;
//   - synth:repeated at its full length (900 frames: identical corridor modules, no real loop):
//     no loop accepted;
//   - --mode fast with a map stage made slow on purpose: the same bytes as lock-step, loops and
//     corrections included (the tracker never runs past a keyframe it asked for).
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tests/support/odometry_run.h"
#include "tests/support/same_trajectory.h"

namespace plumb::test {
namespace {

SynthOptions shortLoop() {
  SynthOptions o = noisySynth("loop", 480);
  o.loop_period_s = 8.0;  // 240 frames per lap
  return o;
}

OdometryRun runScene(const SynthOptions& options, bool loops, std::vector<StampedPose>* gt,
                     RunSettings settings = {}) {
  std::unique_ptr<SyntheticSource> source;
  EXPECT_TRUE(SyntheticSource::create(options, &source).ok());
  if (gt != nullptr) *gt = groundTruth(source->scene(), options.frames);
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

// A starved CPU, made reproducible: the map stage sleeps on every frame (twice as long on a
// keyframe), so a threaded tracker that did not wait would track against an old map. Fast mode
// must still write lock-step's bytes, loop corrections included, and lock-step must write the same
// bytes run after run (three runs with loops, one output).
TEST(LoopClosing, FastModeWritesTheDeterministicBytesWhileTheMapStageLags) {
  const OdometryRun lock_step = runScene(shortLoop(), true, nullptr);
  RunSettings slow;
  slow.mode = runtime::RunMode::kFast;
  slow.on_frame = [](const FrameOutput& out) {
    std::this_thread::sleep_for(std::chrono::milliseconds(out.keyframe ? 6 : 3));
  };
  const OdometryRun fast = runScene(shortLoop(), true, nullptr, slow);
  const OdometryRun lock_step_again = runScene(shortLoop(), true, nullptr);
  ASSERT_TRUE(lock_step.status.ok() && fast.status.ok() && lock_step_again.status.ok());
  // Three runs, one output: lock-step twice (run after run) and fast with a lagging map stage.
  EXPECT_TRUE(sameTrajectory(lock_step_again.trajectory, lock_step.trajectory));
  EXPECT_TRUE(sameTrajectory(lock_step_again.optimized, lock_step.optimized));
  ASSERT_GE(lock_step.stats.loop_corrections_applied, 1u) << "the scene must close a loop for this test";
  EXPECT_EQ(fast.stats.loop_corrections_applied, lock_step.stats.loop_corrections_applied);
  EXPECT_TRUE(sameTrajectory(fast.trajectory, lock_step.trajectory));
  EXPECT_TRUE(sameTrajectory(fast.optimized, lock_step.optimized));
}

}  // namespace
}  // namespace plumb::test
