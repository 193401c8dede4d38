// A synthetic sequence through the fault injector, the supervisor and the whole odometry system:
// the counts match what was injected, and the trajectory continues after the reconnection: every
// frame after it gets a pose and the run ends tracking. Accuracy across the gap is printed, not
// asserted: at the time of writing the odometry drifts on this scene around frames 35-40 even
// without any fault (then relocalizes), so an accuracy bound would test the odometry, not faults.
#include <gtest/gtest.h>

#include "drivers/fault/fault_injecting_source.h"
#include "drivers/fault/resilient_source.h"
#include "drivers/synth/synthetic_scene.h"
#include "tests/support/odometry_run.h"

namespace plumb {
namespace {

TEST(FaultPipeline, TrajectoryContinuesAfterReconnection) {
  SynthOptions synth;
  synth.preset = "textured";
  synth.seed = 7;
  synth.frames = 75;
  std::unique_ptr<SyntheticSource> rendered;
  ASSERT_TRUE(SyntheticSource::create(synth, &rendered).ok());
  const SyntheticScene& scene = rendered->scene();

  auto faulty = std::make_unique<FaultInjectingSource>(
      std::move(rendered), std::vector<FaultEvent>{
                               {15, FaultKind::kDrop, 2},
                               {25, FaultKind::kStall, 3},
                               {40, FaultKind::kDisconnect, /*frames lost*/ 4, /*failed reopens*/ 2},
                           });
  FaultInjectingSource* injector = faulty.get();
  VirtualClock clock;
  ResilientSource source(std::move(faulty), {}, clock);

  SystemOptions options;
  options.output_delay_frames = 0;  // poses as tracked, frame by frame
  test::RunSettings settings;
  settings.keep_outputs = true;
  settings.max_frames = 200;  // a guard: the source ends by itself
  const test::OdometryRun run = test::runOdometry(source, options, settings);
  ASSERT_TRUE(run.status.ok()) << run.status.message();
  bool have_first = false;
  Eigen::Isometry3d T_first_est = Eigen::Isometry3d::Identity();
  uint64_t first_sequence = 0;
  int frames_after_reconnect = 0, posed_after_reconnect = 0;
  TrackingState last_state = TrackingState::kNotInitialized;
  double worst_error_after_reconnect_m = 0, last_error_m = 0;
  for (const FrameOutput& out : run.outputs) {
    last_state = out.state;
    if (out.sequence >= 44) ++frames_after_reconnect;
    if (!out.has_pose) continue;
    if (!have_first) {
      have_first = true;
      T_first_est = out.T_world_cam;
      first_sequence = out.sequence;
      continue;
    }
    if (out.sequence < 44) continue;
    ++posed_after_reconnect;
    // Motion since the first posed frame, estimated vs exact.
    const int i0 = static_cast<int>(first_sequence), i = static_cast<int>(out.sequence);
    const Eigen::Isometry3d gt = scene.T_world_cam(i0).inverse() * scene.T_world_cam(i);
    const Eigen::Isometry3d est = T_first_est.inverse() * out.T_world_cam;
    last_error_m = (gt.translation() - est.translation()).norm();
    worst_error_after_reconnect_m = std::max(worst_error_after_reconnect_m, last_error_m);
  }
  const InjectedFaults& injected = injector->injected();
  const ResilienceStats& stats = source.stats();
  EXPECT_EQ(injected.frames_dropped, 6u);
  EXPECT_EQ(stats.frames_missing, injected.frames_dropped);
  EXPECT_EQ(stats.frames_delivered, 75u - 6u);
  EXPECT_EQ(stats.no_frame_results, 3u);
  EXPECT_EQ(stats.errors, 1u);
  EXPECT_EQ(stats.reopen_failures, 2u);
  EXPECT_EQ(stats.reconnects, 1u);
  // Frames 44..74 arrive after the reconnection: every one of them must carry a pose.
  EXPECT_EQ(frames_after_reconnect, 31);
  EXPECT_EQ(posed_after_reconnect, 31);
  EXPECT_EQ(last_state, TrackingState::kOk);
  std::printf("after reconnection: %d posed frames, translation error vs ground truth: worst %.4f m, "
              "last frame %.4f m\n", posed_after_reconnect, worst_error_after_reconnect_m, last_error_m);
}

}  // namespace
}  // namespace plumb
