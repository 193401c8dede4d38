// The synthetic camera path: smooth, periodic, inside the room, always looking at content.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "drivers/synth/synthetic_scene.h"

namespace plumb {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

double angleDeg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * kRadToDeg; }

std::unique_ptr<SyntheticScene> makeScene(const std::string& preset, uint64_t seed, int frames) {
  SynthOptions options;
  options.preset = preset;
  options.seed = seed;
  options.frames = frames;
  std::unique_ptr<SyntheticScene> scene;
  EXPECT_TRUE(SyntheticScene::create(options, &scene).ok());
  return scene;
}

struct PathStatistics {
  double max_step_m = 0, max_step_deg = 0, max_jerk_m = 0, max_jerk_deg = 0, travel_m = 0;
};

PathStatistics measure(const SyntheticScene& scene, int frames) {
  PathStatistics stats;
  for (int i = 1; i < frames; ++i) {
    const Eigen::Isometry3d T_prev = scene.T_world_cam(i - 1), T = scene.T_world_cam(i);
    const double step = (T.translation() - T_prev.translation()).norm();
    stats.travel_m += step;
    stats.max_step_m = std::max(stats.max_step_m, step);
    stats.max_step_deg = std::max(stats.max_step_deg, angleDeg(T_prev.linear().transpose() * T.linear()));
    if (i + 1 < frames) {  // change of velocity between consecutive steps: no jumps
      const Eigen::Isometry3d T_next = scene.T_world_cam(i + 1);
      const Eigen::Vector3d acceleration = T_next.translation() - 2 * T.translation() + T_prev.translation();
      stats.max_jerk_m = std::max(stats.max_jerk_m, acceleration.norm());
      const double turn_now = angleDeg(T.linear().transpose() * T_next.linear());
      const double turn_before = angleDeg(T_prev.linear().transpose() * T.linear());
      stats.max_jerk_deg = std::max(stats.max_jerk_deg, std::abs(turn_now - turn_before));
    }
  }
  return stats;
}

TEST(SynthTrajectory, SmoothHandHeldMotionOverSeveralMetres) {
  for (uint64_t seed : {1, 2, 3}) {
    auto scene = makeScene("textured", seed, 300);
    const PathStatistics stats = measure(*scene, 300);
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::printf("seed %llu: travel %.2f m in 300 frames, max step %.4f m %.3f deg, max jerk %.5f m %.4f deg\n",
                static_cast<unsigned long long>(seed), stats.travel_m, stats.max_step_m, stats.max_step_deg,
                stats.max_jerk_m, stats.max_jerk_deg);
    EXPECT_GT(stats.travel_m, 3.0) << "several metres in the default 10 s";
    EXPECT_LT(stats.max_step_m, 0.035) << "at most ~1 m/s";
    EXPECT_LT(stats.max_step_deg, 2.5) << "at most ~75 deg/s";
    EXPECT_GT(stats.max_step_deg, 0.2) << "the camera does rotate";
    EXPECT_LT(stats.max_jerk_m, 0.002) << "no jumps in velocity";
    EXPECT_LT(stats.max_jerk_deg, 0.3) << "no jumps in angular velocity";
  }
}

TEST(SynthTrajectory, FastRotationTurnsFasterOnTheSamePath) {
  auto normal = makeScene("textured", 4, 600);
  auto fast = makeScene("fast_rotation", 4, 600);
  const PathStatistics a = measure(*normal, 600), b = measure(*fast, 600);
  std::printf("max rotation per frame: textured %.3f deg, fast_rotation %.3f deg\n", a.max_step_deg, b.max_step_deg);
  EXPECT_GT(b.max_step_deg, 1.8 * a.max_step_deg);
  EXPECT_NEAR(a.travel_m, b.travel_m, 1e-9) << "only the rotation changes";
}

TEST(SynthTrajectory, LoopsRepeatSeamlesslyAndPosesAreRigid) {
  auto scene = makeScene("low_texture", 5, 10000);
  const int lap = 600;  // 20 s at 30 fps
  for (int i : {0, 1, 137, 599}) {
    EXPECT_TRUE(scene->T_world_cam(i).isApprox(scene->T_world_cam(i + lap), 1e-9));
    EXPECT_TRUE(scene->T_world_cam(i).isApprox(scene->T_world_cam(i + 16 * lap), 1e-9));
  }
  // Across the seam (frame 599 -> 600) the motion is as smooth as anywhere else.
  const PathStatistics stats = measure(*scene, 2 * lap + 5);
  EXPECT_LT(stats.max_jerk_m, 0.002);
  for (int i = 0; i < 10000; i += 97) {
    const Eigen::Matrix3d R = scene->T_world_cam(i).linear();
    EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
    EXPECT_NEAR(R.determinant(), 1, 1e-12);
  }
  EXPECT_DOUBLE_EQ(scene->timestamp(9999), 1000.0 + 9999 / 30.0);
}

TEST(SynthTrajectory, StaysInsideTheRoomUpright) {
  // Room interior: x in [0, 7.5], y in [0, 6], z in [0, 2.8] (docs/SYNTHETIC.md).
  for (const char* preset : {"textured", "fast_rotation"}) {
    for (uint64_t seed : {1, 9}) {
      auto scene = makeScene(preset, seed, 600);
      for (int i = 0; i < 600; ++i) {
        const Eigen::Isometry3d T = scene->T_world_cam(i);
        const Eigen::Vector3d p = T.translation();
        EXPECT_TRUE(p.x() > 1.0 && p.x() < 6.5 && p.y() > 1.0 && p.y() < 5.0 && p.z() > 1.1 && p.z() < 1.6)
            << "frame " << i << " at " << p.transpose();
        // Camera y axis (down) points roughly down: no upside-down frames.
        EXPECT_LT(T.linear().col(1).z(), -0.5) << "frame " << i;
      }
    }
  }
}

TEST(SynthTrajectory, ViewAlwaysHoldsContentBeyondMinimumRange) {
  // Render a sample of one lap (both presets share the geometry) and check the view is never
  // blocked by something closer than 0.6 m and always reaches across the room.
  for (const char* preset : {"low_texture", "fast_rotation"}) {
    SynthOptions options;
    options.preset = preset;
    options.seed = 6;
    options.frames = 600;
    options.min_depth_m = 0.0;  // see every surface, however near
    std::unique_ptr<SyntheticScene> scene;
    ASSERT_TRUE(SyntheticScene::create(options, &scene).ok());
    RgbdImage frame;
    for (int i = 0; i < 600; i += 30) {
      ASSERT_TRUE(scene->render(i, frame).ok());
      int near = 0, far = 0, valid = 0;
      for (int y = 0; y < 480; y += 4)
        for (int x = 0; x < 640; x += 4) {
          const double z = frame.depth_raw.at<uint16_t>(y, x) / 5000.0;
          if (z <= 0) continue;
          ++valid;
          near += z < 0.6;
          far += z > 2.5;
        }
      EXPECT_GT(valid, 0.95 * (480 / 4) * (640 / 4)) << preset << " frame " << i;
      EXPECT_LT(near, 0.02 * valid) << preset << " frame " << i;
      EXPECT_GT(far, 0.2 * valid) << preset << " frame " << i << ": the view must reach across the room";
    }
  }
}

}  // namespace
}  // namespace plumb
