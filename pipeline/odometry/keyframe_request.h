#pragma once
// KeyframeRequest: the message from the tracker to the local mapper when a frame should become a
// keyframe (or start a map). It carries a copy of the frame's features, the tracked pose, which
// features were matched to which landmarks (as inliers), and the tracker's per-landmark visibility
// counts since the last snapshot (for culling). Value type, so a ring of them can carry it.
#include <cstdint>

#include <Eigen/Geometry>

#include "pipeline/frontend/frame_features.h"
#include "pipeline/odometry/local_map.h"
#include "platform/fixed_vector.h"

namespace plumb {

struct LandmarkVisibility {
  LandmarkRef ref;
  uint16_t visible = 0;  // frames whose predicted view contained it
  uint16_t found = 0;    // frames where it was matched as an inlier
};

struct KeyframeRequest {
  // true: start a new map (segment) from this frame; the map is cleared first.
  bool start_new_map = false;
  uint64_t frame_sequence = 0;
  double timestamp_s = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  uint64_t local_map_version = 0;  // snapshot the associations refer to
  // The camera's velocity when the frame was tracked, a twist per second of the left perturbation
  // of T_cam_world (T_cam_world(t + dt) ~ exp(twist dt) T_cam_world(t)); zero when unknown. For the
  // timing model error of the published covariances (docs/UNCERTAINTY.md).
  Eigen::Matrix<double, 6, 1> twist_per_s = Eigen::Matrix<double, 6, 1>::Zero();
  FrameFeatures features;
  // Per keypoint / line: the landmark it was matched to as an inlier (id 0 = none).
  std::array<LandmarkRef, kMaxKeypoints> keypoint_landmark{};
  std::array<LandmarkRef, kMaxLines> line_landmark{};
  FixedVector<LandmarkVisibility, kMaxLocalMapPoints> point_visibility;
  FixedVector<LandmarkVisibility, kMaxLocalMapLines> line_visibility;
};

}  // namespace plumb
