// The keyframe decision (pipeline/odometry/keyframe_policy.h) rule by rule, on hand-built
// evidence: each rule alone, on both sides of its threshold, and the two blocking rules winning
// over every triggering one.
#include <gtest/gtest.h>

#include "pipeline/odometry/keyframe_policy.h"

namespace plumb {
namespace {

// Default options with every threshold spelled out, so the boundaries below are readable.
KeyframePolicyOptions options() {
  KeyframePolicyOptions o;
  o.max_frames_between = 30;
  o.min_frames_between = 0;
  o.reference_ratio = 0.75f;
  o.reference_ratio_few_keyframes = 0.4f;
  o.min_tracked_close = 100;
  o.min_untracked_close = 70;
  o.min_inliers = 15;
  return o;
}

// Healthy tracking that asks for nothing: plenty of inliers, all of the reference keyframe's
// landmarks found, enough close points tracked, a few frames after the last keyframe.
KeyframeEvidence quiet() {
  KeyframeEvidence e;
  e.frames_since_keyframe = 5;
  e.inliers = 300;
  e.landmark_inliers = 200;
  e.reference_tracked = 200;
  e.keyframes_in_map = 5;
  e.tracked_close = 150;
  e.untracked_close = 0;
  e.weak = false;
  return e;
}

TEST(KeyframePolicy, QuietTrackingAsksForNothing) {
  EXPECT_FALSE(needNewKeyframe(options(), quiet()));
}

TEST(KeyframePolicy, MaxFramesBetweenTriggersExactlyAtTheLimit) {
  KeyframeEvidence e = quiet();
  e.frames_since_keyframe = 29;
  EXPECT_FALSE(needNewKeyframe(options(), e));
  e.frames_since_keyframe = 30;
  EXPECT_TRUE(needNewKeyframe(options(), e));
  e.frames_since_keyframe = 31;
  EXPECT_TRUE(needNewKeyframe(options(), e));
}

TEST(KeyframePolicy, WeakTrackingTriggers) {
  KeyframeEvidence e = quiet();
  e.weak = true;
  EXPECT_TRUE(needNewKeyframe(options(), e));
}

TEST(KeyframePolicy, ThinTrackingAgainstTheReferenceKeyframe) {
  KeyframeEvidence e = quiet();
  e.reference_tracked = 200;
  // 0.75 * 200 = 150: exactly at the ratio is not thin, one below is.
  e.landmark_inliers = 150;
  EXPECT_FALSE(needNewKeyframe(options(), e));
  e.landmark_inliers = 149;
  EXPECT_TRUE(needNewKeyframe(options(), e));
}

TEST(KeyframePolicy, FewKeyframesUseTheLowerRatio) {
  KeyframeEvidence e = quiet();
  e.reference_tracked = 200;
  e.landmark_inliers = 100;  // thin at 0.75, not at 0.4 (0.4 * 200 = 80)
  e.keyframes_in_map = 2;
  EXPECT_TRUE(needNewKeyframe(options(), e));
  e.keyframes_in_map = 1;
  EXPECT_FALSE(needNewKeyframe(options(), e));
  e.landmark_inliers = 80;
  EXPECT_FALSE(needNewKeyframe(options(), e));
  e.landmark_inliers = 79;
  EXPECT_TRUE(needNewKeyframe(options(), e));
}

TEST(KeyframePolicy, NeedCloseRuleNeedsBothConditions) {
  KeyframeEvidence e = quiet();
  // Tracked close below 100 AND untracked close above 70.
  e.tracked_close = 99;
  e.untracked_close = 71;
  EXPECT_TRUE(needNewKeyframe(options(), e));
  e.tracked_close = 100;  // enough close points tracked
  EXPECT_FALSE(needNewKeyframe(options(), e));
  e.tracked_close = 99;
  e.untracked_close = 70;  // not enough new close structure to add
  EXPECT_FALSE(needNewKeyframe(options(), e));
  e.tracked_close = 0;
  e.untracked_close = 0;
  EXPECT_FALSE(needNewKeyframe(options(), e));
}

TEST(KeyframePolicy, TooFewInliersBlockEveryTrigger) {
  KeyframeEvidence e = quiet();
  e.weak = true;
  e.frames_since_keyframe = 100;
  e.landmark_inliers = 0;
  e.tracked_close = 0;
  e.untracked_close = 500;
  e.inliers = 14;
  EXPECT_FALSE(needNewKeyframe(options(), e));
  e.inliers = 15;  // exactly min_inliers is allowed
  EXPECT_TRUE(needNewKeyframe(options(), e));
}

TEST(KeyframePolicy, MinFramesBetweenBlocksEveryTrigger) {
  KeyframePolicyOptions o = options();
  o.min_frames_between = 3;
  KeyframeEvidence e = quiet();
  e.weak = true;
  e.landmark_inliers = 0;
  e.tracked_close = 0;
  e.untracked_close = 500;
  e.frames_since_keyframe = 2;
  EXPECT_FALSE(needNewKeyframe(o, e));
  e.frames_since_keyframe = 3;  // exactly min_frames_between is allowed
  EXPECT_TRUE(needNewKeyframe(o, e));
}

TEST(KeyframePolicy, EachTriggerAloneSuffices) {
  // Each trigger switched on by itself from the quiet evidence, so no trigger hides another.
  const KeyframePolicyOptions o = options();
  KeyframeEvidence weak = quiet();
  weak.weak = true;
  KeyframeEvidence old = quiet();
  old.frames_since_keyframe = o.max_frames_between;
  KeyframeEvidence thin = quiet();
  thin.landmark_inliers = 10;
  KeyframeEvidence close = quiet();
  close.tracked_close = 10;
  close.untracked_close = 200;
  for (const KeyframeEvidence& e : {weak, old, thin, close}) EXPECT_TRUE(needNewKeyframe(o, e));
}

}  // namespace
}  // namespace plumb
