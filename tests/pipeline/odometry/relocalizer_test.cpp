// Relocalizer (pipeline/odometry/relocalizer.h): a stored keyframe's points seen again from a
// pose some way off relocalize the frame to that pose; features that belong to nothing stored
// do not; a keyframe's refined pose (updatePose) is what the answer is built on.
#include <memory>

#include <gtest/gtest.h>

#include "pipeline/odometry/relocalizer.h"
#include "tests/support/synthetic_features.h"

namespace plumb {
namespace {

using test::pose;
using test::rotationErrorDeg;
using test::translationError;

const Eigen::Isometry3d kKeyframe = pose(15, Eigen::Vector3d(0, 1, 0.2), Eigen::Vector3d(1.0, 0.2, -0.5));
// Farther than tracking could bridge: 8 deg and 15 cm.
const Eigen::Isometry3d kOffset = pose(8, Eigen::Vector3d(0.3, 1, -0.1), Eigen::Vector3d(0.12, -0.05, 0.07));

struct RelocalizerFixture {
  PinholeCamera camera = test::syntheticCamera();
  OdometryOptions options;
  std::unique_ptr<Relocalizer> relocalizer;
  RelocalizerFixture() { relocalizer = std::make_unique<Relocalizer>(camera, options); }
};

TEST(Relocalizer, ReobservedKeyframeGivesTheTruePose) {
  const test::Scene scene = test::makeScene(21, 300, 0, kKeyframe, 1.0, 4.0);
  RelocalizerFixture fx;
  // Unrelated keyframes, and decoys that share 40-100 descriptors with the scene in another
  // geometry (enough to be candidates): the ranking must try the right keyframe first.
  fx.relocalizer->addKeyframe(1, Eigen::Isometry3d::Identity(), *test::unrelatedView(5, 300).features);
  fx.relocalizer->addKeyframe(2, kKeyframe, *test::observe(scene, kKeyframe).features);
  fx.relocalizer->addKeyframe(3, Eigen::Isometry3d::Identity(), *test::unrelatedView(6, 300).features);
  for (uint32_t d = 0; d < 6; ++d) {
    test::Scene decoy = test::makeScene(100 + d, 200, 0, kKeyframe);
    const std::size_t shared = 40 + 10 * d;
    for (std::size_t i = 0; i < shared; ++i) decoy.points[i].descriptor = scene.points[(i * 7 + d) % 300].descriptor;
    fx.relocalizer->addKeyframe(10 + d, kKeyframe, *test::observe(decoy, kKeyframe).features);
  }
  EXPECT_EQ(fx.relocalizer->size(), 9u);

  const Eigen::Isometry3d T_true = kKeyframe * kOffset;
  const test::View view = test::observe(scene, T_true);
  ASSERT_GT(view.features->keypoints.size(), 150u);
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  const RelocResult r = fx.relocalizer->relocalize(*view.features, &T_world_cam);
  ASSERT_TRUE(r.success);
  EXPECT_EQ(r.keyframe_id, 2u);
  EXPECT_EQ(r.candidates_tried, 1);
  EXPECT_GE(r.matches, int(view.features->keypoints.size()) - 5);
  EXPECT_GE(r.refined_inliers, r.matches - 5);
  EXPECT_LT(translationError(T_world_cam, T_true), 1e-4);
  EXPECT_LT(rotationErrorDeg(T_world_cam, T_true), 1e-3);
}

TEST(Relocalizer, KeyframeFarFromTheOriginAndTurned) {
  // The pose is composed from the keyframe's world pose and the frame's pose relative to it: far
  // from the origin and turned, any mix-up of the two is metres off.
  const Eigen::Isometry3d T_keyframe = pose(130, Eigen::Vector3d(0.2, 1, -0.4), Eigen::Vector3d(6.0, -3.0, 4.0));
  const test::Scene scene = test::makeScene(26, 300, 0, T_keyframe, 1.0, 4.0);
  RelocalizerFixture fx;
  fx.relocalizer->addKeyframe(4, T_keyframe, *test::observe(scene, T_keyframe).features);
  const Eigen::Isometry3d T_true = T_keyframe * kOffset;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  const RelocResult r = fx.relocalizer->relocalize(*test::observe(scene, T_true).features, &T_world_cam);
  ASSERT_TRUE(r.success);
  EXPECT_EQ(r.keyframe_id, 4u);
  EXPECT_LT(translationError(T_world_cam, T_true), 1e-4);
  EXPECT_LT(rotationErrorDeg(T_world_cam, T_true), 1e-3);
}

TEST(Relocalizer, UnrelatedFeaturesDoNotRelocalize) {
  const test::Scene scene = test::makeScene(22, 300, 0, kKeyframe);
  RelocalizerFixture fx;
  fx.relocalizer->addKeyframe(1, kKeyframe, *test::observe(scene, kKeyframe).features);
  Eigen::Isometry3d T_world_cam = pose(1, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 2, 3));
  const Eigen::Isometry3d untouched = T_world_cam;
  const RelocResult r = fx.relocalizer->relocalize(*test::unrelatedView(23, 300).features, &T_world_cam);
  EXPECT_FALSE(r.success);
  EXPECT_TRUE(T_world_cam.isApprox(untouched, 1e-15));

  // Nothing stored at all.
  RelocalizerFixture empty;
  EXPECT_FALSE(empty.relocalizer->relocalize(*test::observe(scene, kKeyframe).features, &T_world_cam).success);
}

TEST(Relocalizer, RightDescriptorsInAWrongGeometryDoNotRelocalize) {
  // The same descriptors, but each on another scene point (a shuffled scene): descriptor matching
  // succeeds, no rigid motion explains the correspondences, so RANSAC must refuse.
  const test::Scene scene = test::makeScene(24, 300, 0, kKeyframe);
  RelocalizerFixture fx;
  fx.relocalizer->addKeyframe(1, kKeyframe, *test::observe(scene, kKeyframe).features);
  test::Scene shuffled = scene;
  for (std::size_t i = 0; i < shuffled.points.size(); ++i) {
    shuffled.points[i].P_world = scene.points[(i * 37 + 11) % scene.points.size()].P_world;
  }
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  const RelocResult r = fx.relocalizer->relocalize(*test::observe(shuffled, kKeyframe * kOffset).features, &T_world_cam);
  EXPECT_GT(r.candidates_tried, 0);
  EXPECT_FALSE(r.success);
}

TEST(Relocalizer, UsesTheKeyframePoseRefinedByTheMapper) {
  const test::Scene scene = test::makeScene(25, 300, 0, kKeyframe);
  RelocalizerFixture fx;
  // Stored at a first estimate; the mapper later refines it to kKeyframe.
  const Eigen::Isometry3d first_estimate = pose(2, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.05, 0, 0)) * kKeyframe;
  fx.relocalizer->addKeyframe(9, first_estimate, *test::observe(scene, kKeyframe).features);
  fx.relocalizer->updatePose(9, kKeyframe);
  fx.relocalizer->updatePose(10, first_estimate);  // unknown id: ignored

  const Eigen::Isometry3d T_true = kKeyframe * kOffset;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  const RelocResult r = fx.relocalizer->relocalize(*test::observe(scene, T_true).features, &T_world_cam);
  ASSERT_TRUE(r.success);
  EXPECT_EQ(r.keyframe_id, 9u);
  EXPECT_LT(translationError(T_world_cam, T_true), 1e-4);
  EXPECT_LT(rotationErrorDeg(T_world_cam, T_true), 1e-3);
}

}  // namespace
}  // namespace plumb
