// The fixed lag of map updates (SystemOptions::map_lag_frames, docs/RUNTIME.md "Map updates at a
// fixed lag"): the map a keyframe request of frame k asked for is tracked against from frame k + L
// on, in lock-step and in fast mode alike.
//   - no keyframe is asked for while one is pending: keyframes are at least L frames apart;
//   - fast mode with its map stage made slow writes lock-step's bytes, for L = 1 and L = 3;
//   - fast mode really overlaps: with L = 3 the track stage tracks the two frames after a keyframe
//     while the map stage is still inside that keyframe's frame (it waits there until they are).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "tests/support/odometry_run.h"
#include "tests/support/same_trajectory.h"

namespace plumb::test {
namespace {

constexpr int kFrames = 150;

OdometryRun runTextured(int lag, RunSettings settings) {
  std::unique_ptr<SyntheticSource> source;
  EXPECT_TRUE(SyntheticSource::create(noisySynth("textured", kFrames), &source).ok());
  SystemOptions options = systemOptions(true);
  options.map_lag_frames = lag;
  settings.keep_outputs = true;
  return runOdometry(*source, options, settings);
}

std::vector<uint64_t> keyframeFrames(const OdometryRun& run) {
  std::vector<uint64_t> frames;
  for (const FrameOutput& out : run.outputs) {
    if (out.keyframe) frames.push_back(out.sequence);
  }
  return frames;
}

TEST(MapLag, KeyframesAreTheLagApartAndFastWritesLockStepsBytes) {
  for (int lag : {1, 3}) {
    SCOPED_TRACE("map lag " + std::to_string(lag));
    const OdometryRun lock_step = runTextured(lag, RunSettings{});
    ASSERT_TRUE(lock_step.status.ok()) << lock_step.status.message();
    const std::vector<uint64_t> keyframes = keyframeFrames(lock_step);
    ASSERT_GE(keyframes.size(), 5u);
    for (std::size_t i = 1; i < keyframes.size(); ++i) {
      EXPECT_GE(keyframes[i] - keyframes[i - 1], uint64_t(lag)) << "keyframes at " << keyframes[i - 1] << ", " << keyframes[i];
    }
    RunSettings slow;
    slow.mode = runtime::RunMode::kFast;
    slow.on_frame = [](const FrameOutput& out) {
      std::this_thread::sleep_for(std::chrono::milliseconds(out.keyframe ? 8 : 1));
    };
    const OdometryRun fast = runTextured(lag, slow);
    ASSERT_TRUE(fast.status.ok()) << fast.status.message();
    EXPECT_TRUE(sameTrajectory(fast.trajectory, lock_step.trajectory));
    EXPECT_TRUE(sameTrajectory(fast.optimized, lock_step.optimized));
    EXPECT_EQ(keyframeFrames(fast), keyframes);
  }
}

TEST(MapLag, FastModeTracksTheLagFramesWhileTheMapStageWorks) {
  constexpr int kLag = 3;
  std::atomic<uint64_t> poses{0};
  std::atomic<int> keyframes_checked{0}, overlaps{0};
  RunSettings settings;
  settings.mode = runtime::RunMode::kFast;
  settings.on_pose = [&](const FrameOutput&) { poses.fetch_add(1); };
  // On the map stage's thread, inside a keyframe's frame k (not the first, which is a new map):
  // tracking must reach frame k + kLag - 1 (k + kLag poses) without this frame being finished.
  settings.on_frame = [&](const FrameOutput& out) {
    if (!out.keyframe || out.new_map || out.sequence + kLag >= uint64_t(kFrames)) return;
    keyframes_checked.fetch_add(1);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (poses.load() < out.sequence + kLag && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (poses.load() >= out.sequence + kLag) overlaps.fetch_add(1);
  };
  const OdometryRun run = runTextured(kLag, settings);
  ASSERT_TRUE(run.status.ok()) << run.status.message();
  ASSERT_GE(keyframes_checked.load(), 3);
  EXPECT_EQ(overlaps.load(), keyframes_checked.load());
}

TEST(MapLag, LagOutsideItsRangeIsRefused) {
  for (int lag : {0, -1, SystemOptions::kMaxMapLagFrames + 1}) {
    SystemOptions options;
    options.map_lag_frames = lag;
    const Status st = validate(options);
    EXPECT_FALSE(st.ok()) << lag;
    EXPECT_NE(st.message().find("map lag"), std::string::npos) << st.message();
  }
  SystemOptions options;
  options.map_lag_frames = SystemOptions::kMaxMapLagFrames;
  EXPECT_TRUE(validate(options).ok());
}

}  // namespace
}  // namespace plumb::test
