// Bad or partial input never crashes the front end: a wrong-size or wrong-type image is refused
// (extract() returns false, output empty); a frame without depth gives 2D-only features.
#include <gtest/gtest.h>

#include "pipeline/frontend/feature_extractor.h"
#include "tests/pipeline/frontend_test_support.h"

namespace plumb {
namespace {

TEST(FrontendBadInput, WrongImageIsRefusedAndMissingDepthGives2dOnly) {
  auto scene = test::makeScene("textured", 51);
  ASSERT_TRUE(scene);
  FeatureExtractor extractor(scene->camera(), ExtractorOptions());
  auto features = std::make_unique<FrameFeatures>();
  RgbdImage frame = test::renderFrame(*scene, 0);
  ASSERT_TRUE(extractor.extract(frame, *features));
  ASSERT_GT(features->keypoints.size(), 0u);

  RgbdImage small;
  small.bgr = cv::Mat(240, 320, CV_8UC3, cv::Scalar(0, 0, 0));
  EXPECT_FALSE(extractor.extract(small, *features));
  EXPECT_EQ(features->keypoints.size(), 0u);
  EXPECT_EQ(features->lines.size(), 0u);
  RgbdImage float_image;
  float_image.bgr = cv::Mat(480, 640, CV_32FC1, cv::Scalar(0));
  EXPECT_FALSE(extractor.extract(float_image, *features));
  RgbdImage empty;
  EXPECT_FALSE(extractor.extract(empty, *features));

  // Depth missing or of the wrong size/type: every feature is 2D-only.
  for (const cv::Mat& depth : {cv::Mat(), cv::Mat(100, 100, CV_16UC1, cv::Scalar(5000)),
                               cv::Mat(480, 640, CV_32FC1, cv::Scalar(1.0f))}) {
    RgbdImage no_depth;
    no_depth.bgr = frame.bgr;
    no_depth.depth_raw = depth;
    ASSERT_TRUE(extractor.extract(no_depth, *features));
    ASSERT_GT(features->keypoints.size(), 500u);
    for (const KeypointObservation& kp : features->keypoints) {
      ASSERT_EQ(kp.depth_m, 0.f);
      ASSERT_EQ(kp.u_right, -1.f);
    }
    for (const LineObservation& line : features->lines) {
      ASSERT_FALSE(line.has_3d);
      ASSERT_EQ(line.num_samples, 0);
    }
  }
  // A flat grey image: no features, no crash.
  RgbdImage flat;
  flat.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  ASSERT_TRUE(extractor.extract(flat, *features));
  EXPECT_EQ(features->keypoints.size(), 0u);
  EXPECT_EQ(features->lines.size(), 0u);
}

}  // namespace
}  // namespace plumb
