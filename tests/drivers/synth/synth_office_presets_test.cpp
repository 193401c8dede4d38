// The office presets (docs/SYNTHETIC.md, issue 20): office_loop's lap 2 revisits lap 1 and its
// path stays clear of the furniture; office_pass never comes back; both render deterministically
// and show long straight edges (what the scenes are for).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "drivers/synth/office_layout.h"
#include "drivers/synth/synthetic_scene.h"

namespace plumb {
namespace {

std::unique_ptr<SyntheticScene> makeOfficeScene(const std::string& preset, uint64_t seed) {
  SynthOptions options;
  options.preset = preset;
  options.seed = seed;
  options.frames = presetDefaultFrames(preset);
  std::unique_ptr<SyntheticScene> scene;
  EXPECT_TRUE(SyntheticScene::create(options, &scene).ok());
  return scene;
}

TEST(SynthOfficePresets, LoopRevisitsAndStaysInsideTheRoom) {
  EXPECT_EQ(presetDefaultFrames("office_loop"), 1200);
  for (uint64_t seed : {1, 3}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto scene = makeOfficeScene("office_loop", seed);
    double max_revisit_m = 0;
    for (int i = 0; i < 600; i += 10) {
      const Eigen::Vector3d p = scene->T_world_cam(i).translation();
      max_revisit_m = std::max(max_revisit_m, (scene->T_world_cam(i + 600).translation() - p).norm());
      EXPECT_GT(p.x(), 1.0);
      EXPECT_LT(p.x(), synth::kOfficeWidth - 1.0);
      EXPECT_GT(p.y(), 1.3);  // the workstations' chairs reach y ~1.3 m
      EXPECT_LT(p.y(), synth::kOfficeDepth - 1.0);
      // Outside the meeting table and its chairs (x 3.3..5.7, y 2.6..4.6).
      EXPECT_FALSE(p.x() > 3.0 && p.x() < 6.0 && p.y() > 2.4 && p.y() < 4.8) << "frame " << i;
    }
    EXPECT_LT(max_revisit_m, 0.15);  // lap 2 passes beside lap 1
    EXPECT_LT((scene->T_world_cam(1200).translation() - scene->T_world_cam(0).translation()).norm(), 1e-9);
  }
}

TEST(SynthOfficePresets, PassNeverComesBack) {
  EXPECT_EQ(presetDefaultFrames("office_pass"), 800);
  const auto scene = makeOfficeScene("office_pass", 1);
  for (int i = 90; i < 800; i += 15) {
    const Eigen::Vector3d p = scene->T_world_cam(i).translation();
    for (int j = 0; j + 60 < i; j += 5) {
      EXPECT_GT((scene->T_world_cam(j).translation() - p).norm(), 0.3) << "frame " << i << " near frame " << j;
    }
  }
}

TEST(SynthOfficePresets, RenderDeterministically) {
  for (const char* preset : {"office_loop", "office_pass"}) {
    SCOPED_TRACE(preset);
    const auto a = makeOfficeScene(preset, 2), b = makeOfficeScene(preset, 2);
    RgbdImage x, y;
    ASSERT_TRUE(a->render(120, x).ok());
    ASSERT_TRUE(b->render(120, y).ok());
    ASSERT_EQ(x.bgr.total(), y.bgr.total());
    EXPECT_EQ(std::memcmp(x.bgr.data, y.bgr.data, x.bgr.total() * x.bgr.elemSize()), 0);
    EXPECT_EQ(std::memcmp(x.depth_raw.data, y.depth_raw.data, x.depth_raw.total() * x.depth_raw.elemSize()), 0);
    // Something in view at a usable depth (no frame is a blank wall at arm's length).
    int valid = 0;
    for (int r = 0; r < x.depth_raw.rows; r += 4)
      for (int c = 0; c < x.depth_raw.cols; c += 4) valid += x.depth_raw.at<uint16_t>(r, c) > 0;
    EXPECT_GT(valid, 15000);
  }
}

}  // namespace
}  // namespace plumb
