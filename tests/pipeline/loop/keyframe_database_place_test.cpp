// KeyframeDatabase on real front-end descriptors: lap 2 of the synthetic "loop" scene (Kinect-like
// noise) finds the lap-1 keyframe at the same place, from ORB and LBD words alone.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <memory>

#include "drivers/synth/synthetic_scene.h"
#include "pipeline/frontend/feature_extractor.h"
#include "pipeline/loop/keyframe_database.h"

namespace plumb::loop {
namespace {

constexpr int kLap = 600;

std::unique_ptr<SyntheticScene> noisyScene(const std::string& preset) {
  SynthOptions options;
  options.preset = preset;
  options.seed = 1;
  options.frames = 2 * kLap;
  options.depth_noise = true;
  options.depth_edge_holes = true;
  options.pixel_noise_sigma = 1.0;
  std::unique_ptr<SyntheticScene> scene;
  EXPECT_TRUE(SyntheticScene::create(options, &scene).ok());
  return scene;
}

PlaceDescriptors viewOf(const FrameFeatures& f) {
  return {f.keypoint_descriptors.data(), f.keypoint_descriptors.size(), f.line_descriptors.data(),
          f.line_descriptors.size()};
}

TEST(KeyframeDatabasePlaces, LapTwoFindsLapOne) {
  auto scene = noisyScene("loop");
  ASSERT_TRUE(scene);
  FeatureExtractor extractor(scene->camera(), ExtractorOptions{});
  auto features = std::make_unique<FrameFeatures>();
  RgbdImage frame;
  KeyframeDatabase db(KeyframeDatabaseOptions{});
  // Lap 1: a keyframe every 20 frames (0.67 s, ~0.4 m).
  for (int i = 0; i < kLap; i += 20) {
    ASSERT_TRUE(scene->render(i, frame).ok());
    ASSERT_TRUE(extractor.extract(frame, *features));
    ASSERT_TRUE(db.insert(uint64_t(i), viewOf(*features)).ok());
  }
  // Lap 2 views between lap-1 keyframes (10 frames off the nearest): the nearest keyframe wins.
  int correct = 0, queries = 0;
  for (int k = 10; k < kLap; k += 60) {
    ASSERT_TRUE(scene->render(kLap + k, frame).ok());
    ASSERT_TRUE(extractor.extract(frame, *features));
    PlaceCandidates got;
    db.query(viewOf(*features), PlaceQueryOptions{}, &got);
    ASSERT_GE(got.size(), 2u);
    const bool ok = std::abs(int(got[0].keyframe_id) - k) <= 10;
    correct += ok;
    ++queries;
    std::printf("lap-2 frame %d: best keyframe %llu (score %.3f: points %.3f lines %.3f), next %llu (%.3f)\n",
                kLap + k, (unsigned long long)got[0].keyframe_id, got[0].score, got[0].point_score,
                got[0].line_score, (unsigned long long)got[1].keyframe_id, got[1].score);
  }
  EXPECT_EQ(correct, queries);
}

// For the loop detector's authors: in the corridor of identical modules the database can not
// tell a module from the next one (that is the verifier's job); here is how the scores look.
TEST(KeyframeDatabasePlaces, CorridorLookAlikesScoreHigh) {
  auto scene = noisyScene("repeated");
  ASSERT_TRUE(scene);
  FeatureExtractor extractor(scene->camera(), ExtractorOptions{});
  auto features = std::make_unique<FrameFeatures>();
  RgbdImage frame;
  KeyframeDatabase db(KeyframeDatabaseOptions{});
  for (int i = 0; i < 600; i += 20) {
    ASSERT_TRUE(scene->render(i, frame).ok());
    ASSERT_TRUE(extractor.extract(frame, *features));
    ASSERT_TRUE(db.insert(uint64_t(i), viewOf(*features)).ok());
    if (i < 300) continue;
    // Query with the keyframe's own view, leaving out the last 3 s (the local window).
    PlaceQueryOptions q;
    q.max_candidate_id = uint64_t(i - 90);
    PlaceCandidates got;
    db.query(viewOf(*features), q, &got);
    ASSERT_FALSE(got.empty());
    EXPECT_LE(got[0].keyframe_id, uint64_t(i - 90));
    // One module (3 m) at 0.45 m/s is 200 frames.
    std::printf("corridor frame %d: best earlier keyframe %llu (score %.3f), %d frames back\n", i,
                (unsigned long long)got[0].keyframe_id, got[0].score, i - int(got[0].keyframe_id));
  }
}

}  // namespace
}  // namespace plumb::loop
