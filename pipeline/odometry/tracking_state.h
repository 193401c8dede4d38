#pragma once
// Tracking state of a frame and what the tracker reports about it.
#include <cstdint>

#include <Eigen/Geometry>

namespace plumb {

enum class TrackingState : uint8_t {
  kNotInitialized,  // no map yet (waiting for a frame with enough depth features)
  kOk,              // enough inliers
  kWeak,            // pose kept but support is thin: a keyframe is forced to refresh the map
  kLost,            // pose not trusted: relocalization runs, the frame is marked lost
};

const char* toString(TrackingState state);

struct TrackResult {
  TrackingState state = TrackingState::kNotInitialized;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  int frame_matches = 0;       // point + line matches from the last frame
  int local_map_matches = 0;   // point + line matches added from the local map
  int point_inliers = 0;       // after the final pose optimisation
  int line_inliers = 0;        // lines with a majority of inlier samples
  int landmark_inliers = 0;    // inliers that are map landmarks (not last-frame depth points)
  bool used_motion_fallback = false;  // constant velocity failed; wide / zero-motion retry used
  bool keyframe_requested = false;
  // Covariances of the tracked pose, 6x6 of the left perturbation [rho; phi] of T_cam_world
  // (solver/se3.h), calibrated (docs/UNCERTAINTY.md). covariance_local: relative to the map, the
  // part two consecutive frames do not share, from the final pose-only optimisation (inverse of its
  // robust Gauss-Newton information, scaled by UncertaintyOptions::motion_scale); what the frame-to-
  // frame motion (MAVLink's velocity) builds on. covariance: with respect to the world frame, the
  // reference keyframe's world covariance chained with the frame's relative to it (pose-only scaled
  // by tracked_scale, plus the map error): what is published as the pose's (MAVLink, API,
  // --track-covariance).
  // Invalid when the optimisation did not run or was degenerate (or, for `covariance`, the
  // reference keyframe has no world covariance).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_valid = false;
  Eigen::Matrix<double, 6, 6> covariance_local = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_local_valid = false;
  // The previous tracked frame's pose as the map THIS frame was tracked in places it: the tracker
  // moves its last frame with its reference keyframe when local BA or a loop correction changes
  // the map between two frames. The frame-to-frame motion T_world_previous^-1 T_world_cam is
  // then free of that change, where the difference of two published poses is not (a keyframe's
  // BA moved synth:office_loop's next pose by up to 27 mm: a 0.8 m/s spike in a velocity made
  // from published poses). What MAVLink's velocity is made from (docs/MAVLINK.md).
  bool has_previous = false;
  double previous_timestamp_s = 0.0;
  Eigen::Isometry3d T_world_previous = Eigen::Isometry3d::Identity();
};

}  // namespace plumb
