#include "pipeline/odometry/keyframe_policy.h"

namespace plumb {

bool needNewKeyframe(const KeyframePolicyOptions& options, const KeyframeEvidence& e) {
  if (e.inliers < options.min_inliers) return false;
  if (e.frames_since_keyframe < options.min_frames_between) return false;
  if (e.weak) return true;
  if (e.frames_since_keyframe >= options.max_frames_between) return true;
  const float ratio = e.keyframes_in_map < 2 ? options.reference_ratio_few_keyframes : options.reference_ratio;
  const bool thin = e.landmark_inliers < ratio * float(e.reference_tracked);
  const bool need_close = e.tracked_close < options.min_tracked_close && e.untracked_close > options.min_untracked_close;
  return thin || need_close;
}

}  // namespace plumb
