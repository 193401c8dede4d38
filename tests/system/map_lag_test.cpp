// The fixed lag of map updates (SystemOptions::map_lag_frames and refine_lag_frames, docs/RUNTIME.md
// "Map updates at a fixed lag"): the map a keyframe request of frame k asked for is tracked against
// from frame k + L on, in lock-step and in fast mode alike; split into two (L = 1, M =
// refine_lag_frames >= 1, an option), its fresh map (keyframe inserted, new landmarks, before local
// BA) from k + 1 and the map after k's BA from k + 1 + M.
//   - no keyframe is asked for while one is pending: keyframes are at least L frames apart;
//   - fast mode writes lock-step's bytes with its map stage made slow, for the split update
//     (M = 1), the unsplit one at L = 1 (the default) and at L = 3: a tracker that did not wait for
//     the map it is due would see older maps than lock-step (whose map stage is always ahead: a
//     tracker taking the newest map instead of the due one would differ there too);
//   - fast mode really overlaps: split, the track stage tracks frame k + 1 while the map stage is
//     still inside keyframe frame k (after its BA, before the frame is finished); with L = 3 and no
//     split it tracks k + 1 and k + 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "tests/support/odometry_run.h"
#include "tests/support/same_trajectory.h"

namespace plumb::test {
namespace {

constexpr int kFrames = 150;

struct Lags {
  int map = 1;     // SystemOptions::map_lag_frames
  int refine = 0;  // SystemOptions::refine_lag_frames
  std::string name() const { return "map lag " + std::to_string(map) + ", refine lag " + std::to_string(refine); }
};

OdometryRun runTextured(const Lags& lags, RunSettings settings) {
  std::unique_ptr<SyntheticSource> source;
  EXPECT_TRUE(SyntheticSource::create(noisySynth("textured", kFrames), &source).ok());
  SystemOptions options = systemOptions(true);
  options.map_lag_frames = lags.map;
  options.refine_lag_frames = lags.refine;
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

// Every frame tracked against the same map: the same landmark matches and the same pose, bit for
// bit. Stricter than the output trajectory: a frame tracked against a map that lacks the last
// keyframe's new landmarks can get the same pose from the last frame's depth points.
void expectSameTracking(const OdometryRun& fast, const OdometryRun& lock_step) {
  ASSERT_EQ(fast.outputs.size(), lock_step.outputs.size());
  for (std::size_t i = 0; i < fast.outputs.size(); ++i) {
    const TrackResult& a = fast.outputs[i].track;
    const TrackResult& b = lock_step.outputs[i].track;
    ASSERT_EQ(a.local_map_matches, b.local_map_matches) << "frame " << fast.outputs[i].sequence;
    ASSERT_EQ(a.landmark_inliers, b.landmark_inliers) << "frame " << fast.outputs[i].sequence;
    ASSERT_TRUE(a.T_world_cam.matrix() == b.T_world_cam.matrix()) << "frame " << fast.outputs[i].sequence;
  }
}

void expectSameRun(const OdometryRun& fast, const OdometryRun& lock_step) {
  ASSERT_TRUE(fast.status.ok()) << fast.status.message();
  EXPECT_TRUE(sameTrajectory(fast.trajectory, lock_step.trajectory));
  EXPECT_TRUE(sameTrajectory(fast.optimized, lock_step.optimized));
  EXPECT_EQ(keyframeFrames(fast), keyframeFrames(lock_step));
  expectSameTracking(fast, lock_step);
}

TEST(MapLag, KeyframesAreTheLagApartAndFastWritesLockStepsBytes) {
  for (const Lags& lags : {Lags{1, 1}, Lags{1, SystemOptions::kDefaultRefineLagFrames}, Lags{3, 0}}) {
    SCOPED_TRACE(lags.name());
    const OdometryRun lock_step = runTextured(lags, RunSettings{});
    ASSERT_TRUE(lock_step.status.ok()) << lock_step.status.message();
    const std::vector<uint64_t> keyframes = keyframeFrames(lock_step);
    ASSERT_GE(keyframes.size(), 5u);
    for (std::size_t i = 1; i < keyframes.size(); ++i) {
      EXPECT_GE(keyframes[i] - keyframes[i - 1], uint64_t(lags.map)) << "keyframes at " << keyframes[i - 1] << ", " << keyframes[i];
    }
    // The map stage falls behind just before each keyframe (the synthetic capture, rendering live,
    // is slower than mapping, so the map stage is otherwise always ahead): finishing frame k - 1
    // takes it 250 ms, while the track stage gets to frames k + 1 .. k + L, whose maps it must
    // wait for.
    RunSettings slow_map;
    slow_map.mode = runtime::RunMode::kFast;
    slow_map.on_frame = [&keyframes](const FrameOutput& out) {
      if (std::find(keyframes.begin(), keyframes.end(), out.sequence + 1) != keyframes.end()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
      }
    };
    expectSameRun(runTextured(lags, slow_map), lock_step);
  }
}

TEST(MapLag, FastModeTracksTheLagFramesWhileTheMapStageWorks) {
  // Split: frame k + 1 needs only k's fresh map. Unsplit with L = 3: k + 1 and k + 2 need nothing new.
  for (const Lags& lags : {Lags{1, 1}, Lags{3, 0}}) {
    SCOPED_TRACE(lags.name());
    const uint64_t ahead = uint64_t(lags.refine > 0 ? 1 : lags.map - 1);  // frames tracked past k meanwhile
    std::atomic<uint64_t> poses{0};
    std::atomic<int> keyframes_checked{0}, overlaps{0};
    RunSettings settings;
    settings.mode = runtime::RunMode::kFast;
    settings.on_pose = [&](const FrameOutput&) { poses.fetch_add(1); };
    // On the map stage's thread, inside a keyframe's frame k (not the first, which is a new map):
    // tracking must reach frame k + ahead (k + ahead + 1 poses) without this frame being finished.
    settings.on_frame = [&](const FrameOutput& out) {
      if (!out.keyframe || out.new_map || out.sequence + ahead + 1 >= uint64_t(kFrames)) return;
      keyframes_checked.fetch_add(1);
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
      while (poses.load() < out.sequence + ahead + 1 && std::chrono::steady_clock::now() < give_up) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      if (poses.load() >= out.sequence + ahead + 1) overlaps.fetch_add(1);
    };
    const OdometryRun run = runTextured(lags, settings);
    ASSERT_TRUE(run.status.ok()) << run.status.message();
    ASSERT_GE(keyframes_checked.load(), 3);
    EXPECT_EQ(overlaps.load(), keyframes_checked.load());
  }
}

TEST(MapLag, LagsOutsideTheirRangesAreRefused) {
  for (int lag : {0, -1, SystemOptions::kMaxMapLagFrames + 1}) {
    SystemOptions options;
    options.map_lag_frames = lag;
    options.refine_lag_frames = 0;
    const Status st = validate(options);
    EXPECT_FALSE(st.ok()) << lag;
    EXPECT_NE(st.message().find("map lag"), std::string::npos) << st.message();
  }
  for (int lag : {-1, SystemOptions::kMaxRefineLagFrames + 1}) {
    SystemOptions options;
    options.refine_lag_frames = lag;
    const Status st = validate(options);
    EXPECT_FALSE(st.ok()) << lag;
    EXPECT_NE(st.message().find("refine lag"), std::string::npos) << st.message();
  }
  SystemOptions options;
  options.map_lag_frames = SystemOptions::kMaxMapLagFrames;
  options.refine_lag_frames = 0;
  EXPECT_TRUE(validate(options).ok());
  options.refine_lag_frames = 1;  // split updates need L = 1
  const Status st = validate(options);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("refine lag 0"), std::string::npos) << st.message();
  options.map_lag_frames = 1;
  options.refine_lag_frames = SystemOptions::kMaxRefineLagFrames;
  EXPECT_TRUE(validate(options).ok());
}

}  // namespace
}  // namespace plumb::test
