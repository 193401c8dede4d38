// The output queue (pipeline/odometry/odometry_trajectory.h): frames leave after `delay` newer
// frames, in order, re-expressed against the CURRENT pose of their reference keyframe; lost and
// dropped frames keep their place; flushAll empties it; the delay is bounded by the ring.
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/odometry/odometry_trajectory.h"
#include "tests/support/synthetic_features.h"

namespace plumb {
namespace {

using test::pose;

LocalMap mapWithKeyframes(std::initializer_list<LocalMapKeyframe> keyframes) {
  LocalMap map;
  map.version = 1;
  for (const LocalMapKeyframe& kf : keyframes) (void)map.keyframes.push_back(kf);
  return map;
}

struct Collector {
  std::vector<FinishedFrame> frames;
  auto fn() {
    return [this](const FinishedFrame& f) { frames.push_back(f); };
  }
};

Eigen::Isometry3d frameOffset(int i) {
  return pose(2.0 * i, Eigen::Vector3d(0, 1, 0.2), Eigen::Vector3d(0.01 * i, -0.02 * i, 0.005));
}

TEST(OdometryTrajectory, FramesLeaveAfterDelayNewerFramesInOrder) {
  const LocalMap empty;
  OdometryTrajectory trajectory(3);
  Collector out;
  for (int i = 0; i < 10; ++i) {
    trajectory.push(uint64_t(i), 0.1 * i, true, frameOffset(i), 0, Eigen::Isometry3d::Identity());
    trajectory.popReady(empty, out.fn());
    // After pushing frame i, frames 0 .. i-3 have left (frame i-3 just now).
    ASSERT_EQ(out.frames.size(), std::size_t(std::max(0, i - 2))) << "after frame " << i;
  }
  for (std::size_t k = 0; k < out.frames.size(); ++k) {
    EXPECT_EQ(out.frames[k].sequence, k);
    EXPECT_DOUBLE_EQ(out.frames[k].timestamp_s, 0.1 * double(k));
    EXPECT_TRUE(out.frames[k].valid);
    EXPECT_FALSE(out.frames[k].dropped);
    // No reference: the pose as given.
    EXPECT_TRUE(out.frames[k].T_world_cam.isApprox(frameOffset(int(k)), 1e-12));
  }
  trajectory.flushAll(empty, out.fn());
  ASSERT_EQ(out.frames.size(), 10u);
  for (std::size_t k = 0; k < out.frames.size(); ++k) EXPECT_EQ(out.frames[k].sequence, k);
  // Empty after the flush.
  Collector again;
  trajectory.flushAll(empty, again.fn());
  EXPECT_TRUE(again.frames.empty());
}

TEST(OdometryTrajectory, ZeroDelayOutputsEachFrameAsTracked) {
  OdometryTrajectory trajectory(0);
  // Even when the reference keyframe has moved (a keyframe frame is its own reference, and its
  // local BA runs before the frame leaves): delay 0 is the pose as tracked, bit for bit.
  const Eigen::Isometry3d T_world_ref = pose(10, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 2, 3));
  const Eigen::Isometry3d T_world_ref_moved = pose(11, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1.1, 2, 3));
  const LocalMap map = mapWithKeyframes({{4, T_world_ref_moved}});
  Collector out;
  const Eigen::Isometry3d T_ref_cam = frameOffset(1);
  const Eigen::Isometry3d T_world_cam_tracked = T_world_ref * T_ref_cam;
  trajectory.push(7, 0.7, true, T_world_cam_tracked, 4, T_ref_cam);
  trajectory.popReady(map, out.fn());
  ASSERT_EQ(out.frames.size(), 1u);
  EXPECT_EQ(out.frames[0].sequence, 7u);
  EXPECT_TRUE(out.frames[0].T_world_cam.matrix() == T_world_cam_tracked.matrix());
}

TEST(OdometryTrajectory, PoseFollowsItsReferenceKeyframeMovedByBundleAdjustment) {
  const Eigen::Isometry3d T_world_ref_tracked = pose(5, Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.5, 0, 0));
  const Eigen::Isometry3d T_world_other = pose(-3, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0.4, 0));
  const Eigen::Isometry3d T_ref_cam = frameOffset(3);
  const Eigen::Isometry3d T_world_cam_tracked = T_world_ref_tracked * T_ref_cam;

  OdometryTrajectory trajectory(2);
  trajectory.push(0, 0.0, true, T_world_cam_tracked, 11, T_ref_cam);
  trajectory.push(1, 0.1, true, frameOffset(1), 0, Eigen::Isometry3d::Identity());  // no reference
  trajectory.push(2, 0.2, true, frameOffset(2), 99, frameOffset(5));  // reference no longer in the map

  // Meanwhile local BA moved keyframe 11 (and the map holds another keyframe before it).
  const Eigen::Isometry3d T_world_ref_refined =
      pose(1.5, Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0.03, -0.02, 0.01)) * T_world_ref_tracked;
  const LocalMap map = mapWithKeyframes({{10, T_world_other}, {11, T_world_ref_refined}});
  Collector out;
  trajectory.flushAll(map, out.fn());
  ASSERT_EQ(out.frames.size(), 3u);
  // Re-expressed: the refined keyframe pose composed with the frame's pose relative to it.
  EXPECT_TRUE(out.frames[0].T_world_cam.isApprox(T_world_ref_refined * T_ref_cam, 1e-12));
  EXPECT_GT(test::translationError(out.frames[0].T_world_cam, T_world_cam_tracked), 0.01);
  // No reference, or a reference that left the map: the pose as tracked.
  EXPECT_TRUE(out.frames[1].T_world_cam.isApprox(frameOffset(1), 1e-12));
  EXPECT_TRUE(out.frames[2].T_world_cam.isApprox(frameOffset(2), 1e-12));
}

TEST(OdometryTrajectory, LostAndDroppedFramesKeepTheirPlace) {
  const Eigen::Isometry3d T_world_ref = pose(20, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 0, 0));
  const LocalMap map = mapWithKeyframes({{3, T_world_ref}});
  OdometryTrajectory trajectory(4);
  Collector out;
  trajectory.push(0, 0.0, true, frameOffset(0), 3, frameOffset(0));
  // A lost frame names a reference anyway: without a pose it must not be re-expressed.
  trajectory.push(1, 0.1, false, Eigen::Isometry3d::Identity(), 3, frameOffset(1));
  trajectory.pushDropped(2, 0.2);
  trajectory.push(3, 0.3, true, frameOffset(3), 0, Eigen::Isometry3d::Identity());
  trajectory.pushDropped(4, 0.4);
  trajectory.popReady(map, out.fn());
  ASSERT_EQ(out.frames.size(), 1u);  // 5 pushed, delay 4
  trajectory.flushAll(map, out.fn());
  ASSERT_EQ(out.frames.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(out.frames[k].sequence, k);
    EXPECT_DOUBLE_EQ(out.frames[k].timestamp_s, 0.1 * double(k));
  }
  EXPECT_TRUE(out.frames[0].valid);
  EXPECT_TRUE(out.frames[0].T_world_cam.isApprox(T_world_ref * frameOffset(0), 1e-12));
  EXPECT_FALSE(out.frames[1].valid);
  EXPECT_FALSE(out.frames[1].dropped);
  EXPECT_TRUE(out.frames[1].T_world_cam.isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_FALSE(out.frames[2].valid);
  EXPECT_TRUE(out.frames[2].dropped);
  EXPECT_TRUE(out.frames[3].valid);
  EXPECT_FALSE(out.frames[3].dropped);
  EXPECT_FALSE(out.frames[4].valid);
  EXPECT_TRUE(out.frames[4].dropped);
}

TEST(OdometryTrajectory, RingSlotsAreReusedCleanly) {
  // Many more frames than the ring holds: a slot that held a dropped frame, then a valid one,
  // reports the valid one (no stale flags), and order survives the wrap-around.
  const LocalMap empty;
  OdometryTrajectory trajectory(5);
  Collector out;
  const int n = 3 * OdometryTrajectory::kMaxDelayFrames + 7;
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 1) {
      trajectory.pushDropped(uint64_t(i), 0.01 * i);
    } else {
      trajectory.push(uint64_t(i), 0.01 * i, i % 3 == 0, frameOffset(i % 50), 0, Eigen::Isometry3d::Identity());
    }
    trajectory.popReady(empty, out.fn());
  }
  trajectory.flushAll(empty, out.fn());
  ASSERT_EQ(out.frames.size(), std::size_t(n));
  for (int i = 0; i < n; ++i) {
    const FinishedFrame& f = out.frames[std::size_t(i)];
    ASSERT_EQ(f.sequence, uint64_t(i));
    EXPECT_EQ(f.dropped, i % 3 == 1) << i;
    EXPECT_EQ(f.valid, i % 3 == 0) << i;
  }
}

TEST(OdometryTrajectory, DelayIsBoundedByTheRing) {
  // A delay the ring cannot hold is clamped to kMaxDelayFrames - 1: pushing and popping every
  // frame never holds more than the ring's capacity, so nothing is overwritten.
  const LocalMap empty;
  const int kMax = OdometryTrajectory::kMaxDelayFrames;
  OdometryTrajectory trajectory(10 * kMax);
  Collector out;
  const int n = kMax + 20;
  for (int i = 0; i < n; ++i) {
    trajectory.push(uint64_t(i), 0.0, true, frameOffset(i % 50), 0, Eigen::Isometry3d::Identity());
    trajectory.popReady(empty, out.fn());
    const int expected = std::max(0, i + 1 - (kMax - 1));
    ASSERT_EQ(out.frames.size(), std::size_t(expected)) << "after frame " << i;
  }
  trajectory.flushAll(empty, out.fn());
  ASSERT_EQ(out.frames.size(), std::size_t(n));
  for (int i = 0; i < n; ++i) {
    ASSERT_EQ(out.frames[std::size_t(i)].sequence, uint64_t(i));
    EXPECT_TRUE(out.frames[std::size_t(i)].T_world_cam.isApprox(frameOffset(i % 50), 1e-12)) << i;
  }

  // A negative delay means none.
  OdometryTrajectory immediate(-5);
  Collector now;
  immediate.push(1, 0.0, true, frameOffset(1), 0, Eigen::Isometry3d::Identity());
  immediate.popReady(empty, now.fn());
  EXPECT_EQ(now.frames.size(), 1u);
}

// A caller that does not drain: a full queue refuses the next frame (counted by the system)
// instead of overwriting the oldest, so no frame is silently lost or emitted twice.
TEST(OdometryTrajectory, AFullQueueRefusesInsteadOfOverwriting) {
  const LocalMap empty;
  const int kMax = OdometryTrajectory::kMaxDelayFrames;
  OdometryTrajectory trajectory(300);
  int accepted = 0;
  for (int i = 0; i < kMax + 4; ++i) {
    accepted += trajectory.push(uint64_t(i), 0.0, true, frameOffset(i % 50), 0, Eigen::Isometry3d::Identity());
  }
  EXPECT_EQ(accepted, kMax);
  EXPECT_TRUE(trajectory.full());
  EXPECT_FALSE(trajectory.pushDropped(999, 1.0));
  Collector out;
  trajectory.flushAll(empty, out.fn());
  ASSERT_EQ(out.frames.size(), std::size_t(kMax));
  for (int i = 0; i < kMax; ++i) EXPECT_EQ(out.frames[std::size_t(i)].sequence, uint64_t(i));
}

TEST(OdometryTrajectory, AFrameQueuedBeforeALoopCorrectionKeepsItsWorld) {
  // A loop correction moves the whole map by C while frames wait in the queue. They were tracked
  // (and sent to the robot) before it: they keep the world they were tracked in, BA refinements
  // of their keyframe included; frames queued after the correction are in the corrected world.
  const Eigen::Isometry3d T_world_ref = pose(5, Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.5, 0, 0));
  const Eigen::Isometry3d C = pose(2, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.08, -0.05, 0.02));
  const Eigen::Isometry3d refine = pose(0.3, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.004, 0, 0));
  OdometryTrajectory trajectory(3);
  trajectory.push(0, 0.0, true, T_world_ref * frameOffset(1), 7, frameOffset(1));
  trajectory.setWorld(1, 0, 1, C);  // the mapper applied the correction
  trajectory.push(1, 0.1, true, C * T_world_ref * frameOffset(2), 7, frameOffset(2));
  LocalMap map = mapWithKeyframes({{7, C * refine * T_world_ref}});
  map.loop_corrections = 1;
  map.T_loop_corrections = C;
  Collector out;
  trajectory.flushAll(map, out.fn());
  ASSERT_EQ(out.frames.size(), 2u);
  EXPECT_TRUE(out.frames[0].T_world_cam.isApprox(refine * T_world_ref * frameOffset(1), 1e-12));
  EXPECT_EQ(out.frames[0].loop_epoch, 0u);
  EXPECT_TRUE(out.frames[1].T_world_cam.isApprox(C * refine * T_world_ref * frameOffset(2), 1e-12));
  EXPECT_EQ(out.frames[1].loop_epoch, 1u);
}

}  // namespace
}  // namespace plumb
