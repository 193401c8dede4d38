#pragma once
// Shared helpers of the front-end tests: synthetic frames with exact ground truth, TUM frames.
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "drivers/synth/synthetic_scene.h"
#include "sensor/camera.h"
#include "sensor/rgbd_image.h"

namespace plumb::test {

inline std::unique_ptr<SyntheticScene> makeScene(const std::string& preset, uint64_t seed, bool depth_noise = false,
                                                 bool edge_holes = false) {
  SynthOptions options;
  options.preset = preset;
  options.seed = seed;
  options.frames = 300;
  options.depth_noise = depth_noise;
  options.depth_edge_holes = edge_holes;
  std::unique_ptr<SyntheticScene> scene;
  const Status st = SyntheticScene::create(options, &scene);
  EXPECT_TRUE(st.ok()) << st.message();
  return scene;
}

inline RgbdImage renderFrame(const SyntheticScene& scene, int i) {
  RgbdImage frame;
  const Status st = scene.render(i, frame);
  EXPECT_TRUE(st.ok()) << st.message();
  return frame;
}

inline std::string tumRpyDir() { return std::string(PLUMB_DATASETS_DIR) + "/tum_fr1_rpy_head250"; }

// Frame `index` of fr1/rpy (file names from associations.txt); false when the data is absent.
inline bool loadTumRpyFrame(int index, RgbdImage* out) {
  const std::string dir = tumRpyDir();
  FILE* f = std::fopen((dir + "/associations.txt").c_str(), "r");
  if (!f) return false;
  char line[512];
  int n = 0;
  bool found = false;
  while (std::fgets(line, sizeof line, f)) {
    if (line[0] == '#') continue;
    if (n++ != index) continue;
    double t_rgb = 0, t_depth = 0;
    char rgb[256], depth[256];
    if (std::sscanf(line, "%lf %255s %lf %255s", &t_rgb, rgb, &t_depth, depth) == 4) {
      out->bgr = cv::imread(dir + "/" + rgb, cv::IMREAD_COLOR);
      out->depth_raw = cv::imread(dir + "/" + depth, cv::IMREAD_UNCHANGED);
      out->depth_factor = 5000.0;
      out->timestamp_s = t_rgb;
      found = !out->bgr.empty() && !out->depth_raw.empty();
    }
    break;
  }
  std::fclose(f);
  return found;
}

inline PinholeCamera tum1Camera() {
  PinholeCamera c;
  c.fx = 517.306408; c.fy = 516.469215; c.cx = 318.643040; c.cy = 255.313989;
  c.k1 = 0.262383; c.k2 = -0.953104; c.p1 = -0.005358; c.p2 = 0.002628; c.k3 = 1.163314;
  c.depth_factor = 5000;
  return c;
}

}  // namespace plumb::test
