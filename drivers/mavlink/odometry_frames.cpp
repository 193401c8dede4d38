#include "drivers/mavlink/odometry_frames.h"

#include <algorithm>
#include <cmath>

#include "solver/pose_covariance.h"
#include "solver/se3.h"
#include "solver/se3_jacobians.h"

namespace plumb {

Eigen::Isometry3d forwardCameraBodyFrdExtrinsic() {
  Eigen::Matrix3d R_body_cam;
  // Columns: the camera axes written in body coordinates.
  R_body_cam << 0, 0, 1,  //
      1, 0, 0,            //
      0, 1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_body_cam;
  return T;
}

Eigen::Isometry3d localBodyPose(const Eigen::Isometry3d& T_world_cam, const MavlinkFrameChange& frames) {
  return frames.T_local_world * T_world_cam * frames.T_body_cam.inverse();
}

Eigen::Vector3d eulerRollPitchYaw(const Eigen::Matrix3d& R) {
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

Matrix6d mavlinkPoseJacobian(const Eigen::Isometry3d& T_world_cam, const MavlinkFrameChange& frames) {
  const Eigen::Isometry3d T_local_body = localBodyPose(T_world_cam, frames);
  const Eigen::Vector3d rpy = eulerRollPitchYaw(T_local_body.linear());
  const double sr = std::sin(rpy.x()), cr = std::cos(rpy.x());
  const double cp = std::cos(rpy.y()), tp = std::tan(rpy.y());
  // Body rates -> Euler rates (inverse of w_body = E * [roll' pitch' yaw']).
  Eigen::Matrix3d E_inv;
  E_inv << 1, sr * tp, cr * tp,  //
      0, cr, -sr,                //
      0, sr / cp, cr / cp;

  const Eigen::Matrix3d& R_bc = frames.T_body_cam.linear();
  const Eigen::Vector3d& t_bc = frames.T_body_cam.translation();
  Matrix6d adjoint_body_cam = Matrix6d::Zero();
  adjoint_body_cam.topLeftCorner<3, 3>() = R_bc;
  adjoint_body_cam.topRightCorner<3, 3>() = hat(t_bc) * R_bc;
  adjoint_body_cam.bottomRightCorner<3, 3>() = R_bc;

  Matrix6d d_state_d_eps = Matrix6d::Zero();
  d_state_d_eps.topLeftCorner<3, 3>() = T_local_body.linear();
  d_state_d_eps.bottomRightCorner<3, 3>() = E_inv;
  return -d_state_d_eps * adjoint_body_cam;
}

Matrix6d mavlinkPoseCovariance(const Matrix6d& covariance_delta, const Eigen::Isometry3d& T_world_cam,
                               const MavlinkFrameChange& frames) {
  const Matrix6d J = mavlinkPoseJacobian(T_world_cam, frames);
  return J * covariance_delta * J.transpose();
}

Matrix6d mavlinkVelocityCovariance(const Matrix6d& local_covariance_previous, const Matrix6d& local_covariance,
                                   const Eigen::Isometry3d& T_world_cam_previous, const Eigen::Isometry3d& T_world_cam,
                                   double dt_s, const MavlinkFrameChange& frames) {
  const Eigen::Isometry3d T_cam_world_previous = T_world_cam_previous.inverse();
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const Matrix6d relative = relativePoseCovariance(T_cam_world_previous, T_cam_world, local_covariance_previous,
                                                   local_covariance, Matrix6d::Zero());
  // The body's motion over the interval, in the body frame at the end (what v is expressed in).
  const Eigen::Isometry3d T_body_previous_body =
      frames.T_body_cam * T_cam_world_previous * T_world_cam * frames.T_body_cam.inverse();
  const Eigen::Vector3d motion_in_body = T_body_previous_body.linear().transpose() * T_body_previous_body.translation();
  Matrix6d J = Matrix6d::Identity();
  J.topRightCorner<3, 3>() = hat(motion_in_body);
  J = (J * adjointSE3(frames.T_body_cam)) / dt_s;
  return J * relative * J.transpose();
}

void upperTriangle21(const Matrix6d& m, float out[21]) {
  int k = 0;
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) out[k++] = static_cast<float>(m(r, c));
  }
}

}  // namespace plumb
