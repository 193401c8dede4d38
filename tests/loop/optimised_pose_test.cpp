// LoopRunResult::optimisedPose (docs/LOOP.md "Two trajectories"): a frame keeps its real-time
// pose relative to its reference keyframe's FINAL local-map pose, also when a loop correction was
// applied between the frame's output and the keyframe's retirement (the correction moved the
// whole local map, that keyframe included, by one recorded rigid motion).
#include <gtest/gtest.h>

#include "pipeline/run/odometry_run.h"

namespace plumb::test {
namespace {

Eigen::Isometry3d poseOf(double yaw_deg, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

void expectNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-12) << a.matrix() << "\n vs\n" << b.matrix();
}

// One keyframe (id 7): graph pose G (the loop graph bent the chain), final local-map pose F
// reported in loop epoch 1, i.e. after correction C was applied to the local map.
struct Fixture {
  Eigen::Isometry3d G = poseOf(31, {1.0, 0.2, -0.3});
  Eigen::Isometry3d C = poseOf(0.7, {0.03, -0.01, 0.02});
  Eigen::Isometry3d F = poseOf(30, {1.02, 0.19, -0.28});
  LoopRunResult result;
  Fixture() {
    result.keyframes.emplace_back(7, G);
    LoopRunResult::FinalPose f;
    f.has_final = true;
    f.epoch = 1;
    f.T_world_cam = F;
    result.keyframe_finals.push_back(f);
    result.epoch_corrections.push_back(C);
  }
  FinishedFrame frame(uint64_t epoch, const Eigen::Isometry3d& T_world_cam, const Eigen::Isometry3d& T_ref_cam) const {
    FinishedFrame fr;
    fr.valid = true;
    fr.reference_id = 7;
    fr.loop_epoch = epoch;
    fr.T_world_cam = T_world_cam;
    fr.T_ref_cam = T_ref_cam;
    return fr;
  }
};

TEST(OptimisedPose, AFrameOutputBeforeACorrectionKeepsItsPoseRelativeToTheFinalKeyframe) {
  const Fixture f;
  // Real-time pose in epoch 0's world; the keyframe's pose in that world is C^-1 F. T_ref_cam is
  // what tracking had against the keyframe's pose of that moment (local BA moved it since): the
  // old formula G * T_ref_cam used it and ignored where the frame was relative to the final pose.
  const Eigen::Isometry3d X0 = poseOf(33, {1.3, 0.25, -0.31});
  const Eigen::Isometry3d stale_T_ref_cam = poseOf(2.5, {0.31, 0.04, 0.0});
  Eigen::Isometry3d optimised;
  ASSERT_TRUE(f.result.optimisedPose(f.frame(0, X0, stale_T_ref_cam), &optimised));
  expectNear(optimised, f.G * (f.C.inverse() * f.F).inverse() * X0);
  // The same frame output after the correction (its pose then in epoch 1's world: C X0) lands at
  // the same optimised pose.
  Eigen::Isometry3d after;
  ASSERT_TRUE(f.result.optimisedPose(f.frame(1, f.C * X0, stale_T_ref_cam), &after));
  expectNear(after, optimised);
}

TEST(OptimisedPose, WithoutTheCorrectionsRecordedTheReferenceKeyframesGraphPoseIsUsed) {
  Fixture f;
  f.result.epoch_corrections.clear();  // beyond OdometrySystem::kMaxRecordedCorrections
  const Eigen::Isometry3d T_ref_cam = poseOf(2.5, {0.31, 0.04, 0.0});
  Eigen::Isometry3d optimised;
  ASSERT_TRUE(f.result.optimisedPose(f.frame(0, poseOf(33, {1.3, 0.25, -0.31}), T_ref_cam), &optimised));
  expectNear(optimised, f.G * T_ref_cam);
  // A keyframe final reported BEFORE the frame's epoch cannot be moved forward: same fallback.
  Fixture g;
  ASSERT_TRUE(g.result.optimisedPose(g.frame(2, poseOf(33, {1.3, 0.25, -0.31}), T_ref_cam), &optimised));
  expectNear(optimised, g.G * T_ref_cam);
}

}  // namespace
}  // namespace plumb::test
