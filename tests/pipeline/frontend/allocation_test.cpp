// Steady-state allocation contract of the front end: with the default options extraction, the
// pyramid included (our own downsampler and blur), allocates nothing. The only allocations left
// are inside cv::LineSegmentDetector::detect when use_opencv_lsd is chosen, so then extract() must
// allocate exactly what a bare LSD call on the same level allocates. Matching allocates nothing.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/frontend/feature_extractor.h"
#include "pipeline/frontend/image_pyramid.h"
#include "pipeline/odometry/matcher.h"
#include "platform/allocation_counter.h"
#include "tests/pipeline/frontend_test_support.h"

namespace plumb {
namespace {

TEST(FrontendAllocations, ExtractionAndMatchingAllocateNothing) {
  auto scene = test::makeScene("textured", 31);
  ASSERT_TRUE(scene);
  const RgbdImage a = test::renderFrame(*scene, 0), b = test::renderFrame(*scene, 3);
  const ExtractorOptions options;  // points and lines, our line detector
  FeatureExtractor extractor(scene->camera(), options);
  auto fa = std::make_unique<FrameFeatures>(), fb = std::make_unique<FrameFeatures>();
  ASSERT_TRUE(extractor.extract(a, *fa));  // warm-up (OpenCV lazily initialises its globals)
  ASSERT_TRUE(extractor.extract(b, *fb));
  auto matcher = std::make_unique<ProjectionMatcher>();
  auto matches = std::make_unique<PointMatches>();
  const Eigen::Isometry3d T_b_a = scene->T_world_cam(3).inverse() * scene->T_world_cam(0);
  matcher->matchPointsFrameToFrame(scene->camera(), *fa, T_b_a, *fb, *matches);

  // The pyramid on its own.
  cv::Mat grey;
  cv::cvtColor(a.bgr, grey, cv::COLOR_BGR2GRAY);
  ImagePyramid pyramid(grey.cols, grey.rows, options.num_levels, options.scale_factor);
  pyramid.build(grey);
  AllocationScope pyramid_scope;
  pyramid.build(grey);
  const uint64_t pyramid_allocations = pyramid_scope.count();
  EXPECT_EQ(pyramid_allocations, 0u);

  AllocationScope scope;
  ASSERT_TRUE(extractor.extract(a, *fa));
  const uint64_t extract_allocations = scope.count();
  AllocationScope match_scope;
  const int n = matcher->matchPointsFrameToFrame(scene->camera(), *fa, T_b_a, *fb, *matches);
  EXPECT_EQ(match_scope.count(), 0u);
  EXPECT_EQ(extract_allocations, 0u);
  EXPECT_GT(n, 100);
  EXPECT_GT(fa->keypoints.size(), 500u);
  EXPECT_GT(fa->lines.size(), 50u);
}

TEST(FrontendAllocations, WithOpenCvLsdOnlyTheLsdAllocates) {
  // OpenCV serial, as a run session sets it (pipeline/run/run_session.cpp): the allocation count is
  // process-wide, and OpenCV's worker threads (cvtColor's parallel_for_) otherwise add a few
  // allocations of their own now and then, depending on timing.
  const int opencv_threads = cv::getNumThreads();
  cv::setNumThreads(0);
  struct Restore {
    int threads;
    ~Restore() { cv::setNumThreads(threads); }
  } restore{opencv_threads};
  auto scene = test::makeScene("textured", 32);
  ASSERT_TRUE(scene);
  const RgbdImage frame = test::renderFrame(*scene, 7);
  ExtractorOptions options;
  options.use_opencv_lsd = true;
  FeatureExtractor extractor(scene->camera(), options);
  auto features = std::make_unique<FrameFeatures>();
  ASSERT_TRUE(extractor.extract(frame, *features));
  auto matcher = std::make_unique<ProjectionMatcher>();
  auto line_matches = std::make_unique<LineMatches>();
  matcher->matchLinesFrameToFrame(scene->camera(), *features, Eigen::Isometry3d::Identity(), *features, *line_matches);

  AllocationScope scope;
  ASSERT_TRUE(extractor.extract(frame, *features));
  const uint64_t extract_allocations = scope.count();
  AllocationScope match_scope;
  const int n = matcher->matchLinesFrameToFrame(scene->camera(), *features, Eigen::Isometry3d::Identity(), *features,
                                                *line_matches);
  EXPECT_EQ(match_scope.count(), 0u);
  EXPECT_GT(n, 20);

  // The same LSD call by itself, on the same pyramid level, into a reserved vector.
  cv::Mat grey;
  cv::cvtColor(frame.bgr, grey, cv::COLOR_BGR2GRAY);
  ImagePyramid pyramid(grey.cols, grey.rows, options.num_levels, options.scale_factor);
  pyramid.build(grey);
  AllocationScope pyramid_scope;
  pyramid.build(grey);
  const uint64_t pyramid_allocations = pyramid_scope.count();
  auto lsd = cv::createLineSegmentDetector(cv::LSD_REFINE_NONE, 1.0, 0.6, 2.0, 22.5, 0.0, 0.7, 1024);
  std::vector<cv::Vec4f> segments;
  segments.reserve(8192);
  lsd->detect(pyramid.level(options.line_level), segments);
  AllocationScope lsd_scope;
  lsd->detect(pyramid.level(options.line_level), segments);
  const uint64_t lsd_allocations = lsd_scope.count();
  std::printf("extract() allocations per frame: %llu = pyramid %llu + LSD %llu\n",
              static_cast<unsigned long long>(extract_allocations), static_cast<unsigned long long>(pyramid_allocations),
              static_cast<unsigned long long>(lsd_allocations));
  EXPECT_EQ(pyramid_allocations, 0u);
  EXPECT_EQ(extract_allocations, lsd_allocations);
}

}  // namespace
}  // namespace plumb
