// Loss and recovery: blank frames in the middle of a sequence lose tracking; the system marks
// them lost, relocalizes against its stored keyframes when real frames return, and goes on.
#include <gtest/gtest.h>

#include "tests/system/odometry_test_util.h"

namespace plumb::test {
namespace {

TEST(OdometryRecovery, RelocalizesAfterBlankFramesAndMarksThemLost) {
  constexpr int kBefore = 60, kBlank = 6, kTotal = 110;
  std::unique_ptr<SyntheticScene> scene;
  ASSERT_TRUE(SyntheticScene::create(noisySynth("textured", kTotal), &scene).ok());
  auto system = std::make_unique<OdometrySystem>(scene->camera(), systemOptions(true));
  OdometryRun run;
  RgbdImage image;
  for (int i = 0; i < kTotal; ++i) {
    ASSERT_TRUE(scene->render(i, image).ok());
    image.sequence = uint64_t(i);
    if (i >= kBefore && i < kBefore + kBlank) {  // sensor covered: no image, no depth
      image.bgr.setTo(cv::Scalar::all(0));
      image.depth_raw.setTo(cv::Scalar::all(0));
    }
    system->processImage(image);
    collect(*system, &run);
  }
  system->finish([&run](const FinishedFrame& f) {
    run.trajectory.push_back(StampedPose{f.timestamp_s, f.T_world_cam, f.valid});
  }, [](const RetiredKeyframe&) {});
  ASSERT_EQ(run.trajectory.size(), std::size_t(kTotal));
  for (int i = kBefore; i < kBefore + kBlank; ++i) EXPECT_FALSE(run.trajectory[i].valid) << "frame " << i;
  for (int i = kBefore + kBlank; i < kTotal; ++i) EXPECT_TRUE(run.trajectory[i].valid) << "frame " << i;
  const OdometryStats& stats = system->stats();
  EXPECT_EQ(stats.frames_lost, uint64_t(kBlank));
  EXPECT_GE(stats.relocalizations, 1u);
  EXPECT_EQ(stats.segments, 1u);  // relocalized: no new map was needed
  // The relocalized poses continue the same world frame.
  EXPECT_LT(ateRmse(groundTruth(*scene, kTotal), run.trajectory), 0.02);
}

TEST(OdometryRecovery, NewMapSegmentWhenRelocalizationKeepsFailing) {
  // Frames of a different scene (another seed) after the blank: no stored keyframe matches them,
  // so after M lost frames a new map starts and the trajectory continues.
  constexpr int kFirst = 40, kSecond = 40;
  std::unique_ptr<SyntheticScene> a, b;
  ASSERT_TRUE(SyntheticScene::create(noisySynth("textured", kFirst), &a).ok());
  SynthOptions other = noisySynth("low_texture", kSecond);
  other.seed = 7;
  ASSERT_TRUE(SyntheticScene::create(other, &b).ok());
  SystemOptions options = systemOptions(true);
  auto system = std::make_unique<OdometrySystem>(a->camera(), options);
  RgbdImage image;
  OdometryRun run;
  for (int i = 0; i < kFirst + kSecond; ++i) {
    ASSERT_TRUE((i < kFirst ? a->render(i, image) : b->render(i - kFirst, image)).ok());
    image.timestamp_s = 1000.0 + i / 30.0;
    image.sequence = uint64_t(i);
    system->processImage(image);
    collect(*system, &run);
  }
  const OdometryStats& stats = system->stats();
  EXPECT_EQ(stats.segments, 2u);
  EXPECT_LE(stats.frames_lost, uint64_t(options.odometry.relocalizer.max_lost_frames_before_new_map));
  EXPECT_GT(stats.frames_ok, uint64_t(kFirst + kSecond - 15));
}

}  // namespace
}  // namespace plumb::test
