#pragma once
// What a keyframe publishes about its uncertainty besides the marginal of its last local BA
// (docs/UNCERTAINTY.md). All 6x6 matrices are covariances in solver/se3.h's tangent order
// [rho(3) phi(3)]; see solver/pose_covariance.h for the algebra.
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plumb {

struct KeyframeUncertainty {
  // The relative pose to the previous keyframe of the map (the largest id below this one),
  // T_previous_this = T_cam_prev_world * T_cam_this_world^-1, as the last local BA that held BOTH
  // keyframes left them, and the covariance of its right perturbation from that BA's JOINT
  // marginal (cross-covariance included). previous_id 0: none (first keyframe of a map, or no BA
  // held both yet).
  uint32_t previous_id = 0;
  double previous_timestamp_s = 0;
  Eigen::Isometry3d T_previous_this = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> relative_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // Covariance of the left perturbation of T_cam_world with respect to the WORLD frame (the map's
  // first keyframe, exact by definition): the previous keyframe's, chained through the relative
  // covariance of the BA at this keyframe's insertion. It grows with the distance travelled, as
  // the drift of an odometry does; the tracked pose's published covariance builds on it.
  Eigen::Matrix<double, 6, 6> world_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool world_covariance_valid = false;
  // The camera's velocity when the keyframe was tracked (KeyframeRequest::twist_per_s).
  Eigen::Matrix<double, 6, 1> twist_per_s = Eigen::Matrix<double, 6, 1>::Zero();

  bool hasRelative() const { return previous_id != 0; }
};

}  // namespace plumb
