// The two presets for loop closing: "loop" (two laps; lap 2 revisits lap 1's views a little
// apart, the path closes) and "repeated" (a corridor of identical modules walked one way: looks
// like a loop, is not one).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "drivers/synth/corridor_layout.h"
#include "drivers/synth/frame_renderer.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/synth/synthetic_scene.h"

namespace plumb {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr int kLap = 600;  // 20 s at 30 fps

std::unique_ptr<SyntheticScene> makeScene(const std::string& preset, uint64_t seed, int frames) {
  SynthOptions options;
  options.preset = preset;
  options.seed = seed;
  options.frames = frames;
  std::unique_ptr<SyntheticScene> scene;
  EXPECT_TRUE(SyntheticScene::create(options, &scene).ok());
  return scene;
}

double angleDeg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * kRadToDeg; }

// Fraction of frame a's valid depth pixels that, moved with the ground truth into frame b, land
// inside b's image in front of it: how much of a's view b sees again.
double viewOverlap(const SyntheticScene& scene, int a, int b) {
  RgbdImage image;
  EXPECT_TRUE(scene.render(a, image).ok());
  const PinholeCamera& camera = scene.camera();
  const Eigen::Isometry3d T_b_a = scene.T_world_cam(b).inverse() * scene.T_world_cam(a);
  int valid = 0, seen = 0;
  for (int y = 0; y < image.depth_raw.rows; y += 8)
    for (int x = 0; x < image.depth_raw.cols; x += 8) {
      const uint16_t raw = image.depth_raw.at<uint16_t>(y, x);
      if (raw == 0) continue;
      ++valid;
      const Eigen::Vector3d P_b = T_b_a * camera.unproject(x, y, raw / image.depth_factor);
      if (P_b.z() < 0.3) continue;
      const Eigen::Vector2d uv = camera.project(P_b);
      seen += uv.x() >= 0 && uv.x() < camera.width && uv.y() >= 0 && uv.y() < camera.height;
    }
  return valid ? double(seen) / valid : 0;
}

TEST(SynthLoopPreset, ClosesAfterTwoLapsAndLapTwoRevisitsLapOne) {
  EXPECT_EQ(presetDefaultFrames("loop"), 2 * kLap);
  for (uint64_t seed : {1, 2}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    auto scene = makeScene("loop", seed, 2 * kLap);
    // The path closes: frame 1200 is frame 0, and it goes on periodically.
    EXPECT_TRUE(scene->T_world_cam(0).isApprox(scene->T_world_cam(2 * kLap), 1e-9));
    EXPECT_TRUE(scene->T_world_cam(17).isApprox(scene->T_world_cam(17 + 4 * kLap), 1e-9));
    // ... but after one lap it is near, not at, the start: a revisit, not a replay.
    double sum_m = 0, max_m = 0, max_deg = 0, travel_m = 0, max_step_m = 0;
    for (int i = 0; i < kLap; ++i) {
      const Eigen::Isometry3d T1 = scene->T_world_cam(i), T2 = scene->T_world_cam(i + kLap);
      const double d = (T1.translation() - T2.translation()).norm();
      sum_m += d;
      max_m = std::max(max_m, d);
      max_deg = std::max(max_deg, angleDeg(T1.linear().transpose() * T2.linear()));
    }
    for (int i = 1; i < 2 * kLap; ++i) {
      const double step = (scene->T_world_cam(i).translation() - scene->T_world_cam(i - 1).translation()).norm();
      travel_m += step;
      max_step_m = std::max(max_step_m, step);
      const Eigen::Isometry3d T = scene->T_world_cam(i);
      const Eigen::Vector3d p = T.translation();
      // Room interior x in [0, 7.5], y in [0, 6]; furniture stands up to 0.6 m from the walls.
      EXPECT_TRUE(p.x() > 1.1 && p.x() < 6.4 && p.y() > 1.0 && p.y() < 5.0 && p.z() > 1.1 && p.z() < 1.6)
          << "frame " << i << " at " << p.transpose();
      EXPECT_LT(T.linear().col(1).z(), -0.5) << "upright, frame " << i;
    }
    const double mean_m = sum_m / kLap;
    std::printf("seed %llu: lap 2 vs lap 1 mean %.3f m, max %.3f m, max %.2f deg; travel %.1f m, max step %.4f m\n",
                (unsigned long long)seed, mean_m, max_m, max_deg, travel_m, max_step_m);
    EXPECT_GT(mean_m, 0.01);
    EXPECT_LT(max_m, 0.25);
    EXPECT_LT(max_deg, 12.0);
    EXPECT_GT(travel_m, 20.0) << "twice around the room";
    EXPECT_LT(max_step_m, 0.035) << "at most ~1 m/s";
    // Lap 2 sees again what lap 1 saw.
    for (int i : {0, 150, 333, 480}) {
      const double overlap = viewOverlap(*scene, i, i + kLap);
      EXPECT_GT(overlap, 0.75) << "frame " << i << " vs " << i + kLap;
      // A quarter lap later the camera faces another wall: the overlap test can fail.
      EXPECT_LT(viewOverlap(*scene, i, i + kLap / 4), 0.3) << "frame " << i;
    }
  }
}

TEST(SynthLoopPreset, ViewIsNeverBlockedAndHasTexture) {
  SynthOptions options;
  options.preset = "loop";
  options.seed = 3;
  options.frames = 2 * kLap;
  options.min_depth_m = 0.0;
  std::unique_ptr<SyntheticScene> scene;
  ASSERT_TRUE(SyntheticScene::create(options, &scene).ok());
  RgbdImage frame;
  for (int i = 0; i < 2 * kLap; i += 60) {
    ASSERT_TRUE(scene->render(i, frame).ok());
    int valid = 0, near = 0, total = 0;
    for (int y = 0; y < 480; y += 4)
      for (int x = 0; x < 640; x += 4, ++total) {
        const double z = frame.depth_raw.at<uint16_t>(y, x) / 5000.0;
        if (z <= 0) continue;
        ++valid;
        near += z < 0.5;
      }
    EXPECT_GT(valid, 0.95 * total) << "frame " << i;
    EXPECT_LT(near, 0.02 * valid) << "frame " << i;
  }
}

TEST(SynthLoopPreset, SpecWithoutACountRendersThePresetsLength) {
  for (const auto& [spec, frames] : std::vector<std::pair<std::string, int>>{
           {"synth:loop", 1200}, {"synth:loop:4", 1200}, {"synth:loop:4:300", 300},
           {"synth:repeated", 900}, {"synth:textured:2", 300}, {"synth:low_texture:2:77", 77}}) {
    SynthOptions options;
    ASSERT_TRUE(parseSynthSpec(spec, &options).ok()) << spec;
    EXPECT_EQ(options.frames, frames) << spec;
  }
}

TEST(SynthRepeatedPreset, WalksOneWayDownTheCorridor) {
  EXPECT_EQ(presetDefaultFrames("repeated"), 900);
  EXPECT_EQ(presetDefaultFrames("textured"), 300);
  EXPECT_EQ(presetDefaultFrames("nonsense"), 0);
  auto scene = makeScene("repeated", 1, 900);
  double travel_x = 0;
  for (int i = 1; i < 3000; ++i) {
    const Eigen::Isometry3d T0 = scene->T_world_cam(i - 1), T = scene->T_world_cam(i);
    const Eigen::Vector3d p = T.translation();
    EXPECT_GE(p.x(), T0.translation().x()) << "never back, frame " << i;
    EXPECT_TRUE(p.x() > 1.0 && p.x() < synth::kCorridorLength - 2.0 && p.y() > 0.9 &&
                p.y() < synth::kCorridorWidth - 0.9 && p.z() > 1.2 && p.z() < 1.6)
        << "frame " << i << " at " << p.transpose();
    EXPECT_LT(T.linear().col(1).z(), -0.5) << "upright, frame " << i;
    if (i < 900) travel_x += p.x() - T0.translation().x();
  }
  EXPECT_GT(travel_x, 4 * synth::kCorridorModuleLength) << "the default run passes several identical modules";
  // No real revisit: frames 3 s apart are over a metre apart.
  for (int i = 0; i + 90 < 900; i += 7)
    EXPECT_GT((scene->T_world_cam(i + 90).translation() - scene->T_world_cam(i).translation()).norm(), 1.0);
}

// The modules are copies: the same view one module further on renders the same image, except the
// sign beside the door, which is the only thing that tells modules apart.
TEST(SynthRepeatedPreset, ModulesLookAlikeExceptTheirSigns) {
  const synth::SceneModel model = synth::buildCorridor(synth::CorridorLayoutOptions{});
  const PinholeCamera camera = synthCamera();
  synth::FrameRenderer renderer(model, camera);
  // Facing the north wall square on, 1.2 m away, at a door and its sign (module 3, then 4).
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() << 1, 0, 0,  //
      0, 0, 1,                      //
      0, -1, 0;                     // x right = +x, y down = -z, z forward = +y (north)
  auto render = [&](double x) {
    T_world_cam.translation() = Eigen::Vector3d(x, synth::kCorridorWidth / 2, 1.45);
    renderer.render(T_world_cam);
    return renderer.colour().clone();
  };
  const double door_right = 3 * synth::kCorridorModuleLength + 0.7 + 0.9;
  const cv::Mat a = render(door_right), b = render(door_right + synth::kCorridorModuleLength);
  const cv::Mat c = render(door_right + 0.5);  // not a module apart: a different view
  auto fractionDiffering = [](const cv::Mat& x, const cv::Mat& y) {
    int differ = 0;
    for (int r = 0; r < x.rows; ++r)
      for (int col = 0; col < x.cols; ++col)
        differ += cv::norm(x.at<cv::Vec3f>(r, col) - y.at<cv::Vec3f>(r, col), cv::NORM_INF) > 12;
    return double(differ) / x.total();
  };
  const double copies = fractionDiffering(a, b), shifted = fractionDiffering(a, c);
  std::printf("pixels differing by > 12 levels: next module %.4f, 0.5 m shift %.4f\n", copies, shifted);
  EXPECT_GT(copies, 0.005) << "the signs differ";
  EXPECT_LT(copies, 0.08) << "everything else is a copy";
  EXPECT_GT(shifted, 0.3) << "the comparison can fail";
}

}  // namespace
}  // namespace plumb
