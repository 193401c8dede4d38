#pragma once
// Stamped pose covariances as plumb publishes them, the contract between the pipeline (which
// fills them: pipeline/odometry/published_covariance.h) and drivers/trajectory (which writes and
// reads them as covariance files: covariance_io.h, and checks them: evaluate_nees.h), like
// stamped_pose.h for poses. Every 6x6 is in solver/se3.h's tangent order [rho(3) phi(3)];
// docs/UNCERTAINTY.md says what each describes.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plumb {

// A keyframe as it leaves the map.
struct StampedCovariance {
  double timestamp = 0;
  bool valid = false;  // false: local BA never gave a covariance
  // The marginal from the last local BA that optimised it (left perturbation of T_cam_world).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // Optional (valid only with `valid`): the relative pose to the previous keyframe,
  // T_previous_this = T_cam_prev_world T_cam_this_world^-1, and the covariance of its right
  // perturbation from the joint marginal of a BA that held both.
  bool has_relative = false;
  double previous_timestamp = 0;
  Eigen::Isometry3d T_previous_this = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> relative_covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

// A tracked frame as MAVLink sends it.
struct StampedTrackedCovariance {
  double timestamp = 0;
  bool valid = false;  // false: a pose without a covariance
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();        // in the world
  Eigen::Matrix<double, 6, 6> covariance_local = Eigen::Matrix<double, 6, 6>::Zero();  // to the map
  // Optional: the previous frame's pose in this frame's map (TrackResult::T_world_previous), from
  // which MAVLink's velocity is made; a file without it (older plumb) gives the published poses'
  // difference.
  bool has_previous = false;
  double previous_timestamp = 0;
  Eigen::Isometry3d T_world_previous = Eigen::Isometry3d::Identity();
};

}  // namespace plumb
