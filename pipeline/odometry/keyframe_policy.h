#pragma once
// The keyframe decision, after ORB-SLAM2's RGB-D rules (Tracking::NeedNewKeyFrame) for a local
// mapper that is always idle (single-threaded lock-step):
//   - never with fewer than `min_inliers` inliers, nor within `min_frames_between` of the last one;
//   - always after `max_frames_between` frames;
//   - otherwise when tracking thins out: landmark inliers fall below `reference_ratio` of the
//     landmarks the reference keyframe tracks, or too few close points are tracked while many
//     close points with depth are not (the RGB-D "need close" rule, which keeps near structure —
//     the well-conditioned part of an RGB-D map — in the map).
#include "pipeline/odometry/odometry_options.h"

namespace plumb {

struct KeyframeEvidence {
  int frames_since_keyframe = 0;
  int inliers = 0;               // every inlier of the final pose optimisation
  int landmark_inliers = 0;      // inliers that are map landmarks
  int reference_tracked = 0;     // landmarks the reference keyframe tracks
  int keyframes_in_map = 0;
  int tracked_close = 0;         // close keypoints matched to landmarks
  int untracked_close = 0;       // close keypoints with depth not matched to a landmark
  bool weak = false;             // tracking state weak: insert to refresh the map
};

bool needNewKeyframe(const KeyframePolicyOptions& options, const KeyframeEvidence& evidence);

}  // namespace plumb
