// The presets differ the way the paper needs: "low_texture" has far fewer corners than "textured"
// on the very same geometry, but still many long straight edges.
#include <gtest/gtest.h>

#include <cstdio>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "drivers/synth/synthetic_scene.h"

namespace plumb {
namespace {

struct FeatureCounts {
  int corners = 0;
  int long_lines = 0;  // LSD segments of at least 40 px
};

FeatureCounts countFeatures(const std::string& preset, int frame) {
  SynthOptions options;
  options.preset = preset;
  options.seed = 3;
  std::unique_ptr<SyntheticScene> scene;
  EXPECT_TRUE(SyntheticScene::create(options, &scene).ok());
  RgbdImage image;
  EXPECT_TRUE(scene->render(frame, image).ok());
  cv::Mat grey;
  cv::cvtColor(image.bgr, grey, cv::COLOR_BGR2GRAY);
  FeatureCounts counts;
  std::vector<cv::KeyPoint> corners;
  cv::FAST(grey, corners, 20, true);
  counts.corners = static_cast<int>(corners.size());
  std::vector<cv::Vec4f> segments;
  cv::createLineSegmentDetector()->detect(grey, segments);
  for (const cv::Vec4f& s : segments)
    counts.long_lines += std::hypot(s[2] - s[0], s[3] - s[1]) >= 40.0;
  return counts;
}

TEST(SynthFeatures, LowTextureHasFewCornersButManyLongLines) {
  for (int frame : {0, 100, 200, 300, 400, 500}) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    const FeatureCounts textured = countFeatures("textured", frame);
    const FeatureCounts low = countFeatures("low_texture", frame);
    std::printf("frame %d: FAST corners textured %d, low_texture %d; LSD >= 40 px textured %d, low_texture %d\n", frame,
                textured.corners, low.corners, textured.long_lines, low.long_lines);
    EXPECT_GT(textured.corners, 1000);
    EXPECT_LT(low.corners * 4, textured.corners) << low.corners << " vs " << textured.corners;
    EXPECT_GE(low.long_lines, 25) << "the low-texture case must be rich in lines";
  }
}

}  // namespace
}  // namespace plumb
