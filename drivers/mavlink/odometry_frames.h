#pragma once
// Frame change and covariance conversion from plumb's poses to MAVLink ODOMETRY.
//
// Frames (docs/MAVLINK.md has the full derivation):
//   world W  plumb's world: the camera frame of the first frame (x right, y down, z forward).
//   cam   C  the camera (same optical axes), pose T_world_cam.
//   body  B  the vehicle, FRD (x forward, y right, z down); the camera is mounted at T_body_cam.
//   local L  the MAVLink pose frame (LOCAL_FRD, or LOCAL_NED when the user aligns it): by default
//            the body frame at the moment the camera was at the world origin, so
//            T_local_world = T_body_cam and the first published position is 0.
//
//   T_local_body = T_local_world * T_world_cam * T_cam_body
//
// Covariance: plumb's 6x6 covariance is of the LEFT perturbation delta = [rho; phi] of
// T_cam_world (solver/se3.h). Since T_world_cam <- T_world_cam exp(-delta),
//
//   T_local_body <- T_local_body * exp(eps),   eps = -Ad(T_body_cam) * delta,
//   Ad(T) = [ R  [t]x R ; 0  R ]   for [rho; phi] ordering,
//
// and to first order position moves by R_local_body * eps_rho while the ZYX Euler angles move by
// E^-1 * eps_phi, where E maps Euler-angle rates to body rates. So
//
//   J = [ R_local_body  0 ; 0  E^-1 ] * (-Ad(T_body_cam)),   Sigma_mav = J Sigma_delta J^T
//
// for the MAVLink states [x, y, z, roll, pitch, yaw].
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "solver/types.h"

namespace plumb {

// Default extrinsic: a forward-looking camera at the body origin (camera z = body x forward,
// camera x = body y right, camera y = body z down).
Eigen::Isometry3d forwardCameraBodyFrdExtrinsic();

struct MavlinkFrameChange {
  Eigen::Isometry3d T_body_cam = forwardCameraBodyFrdExtrinsic();
  Eigen::Isometry3d T_local_world = forwardCameraBodyFrdExtrinsic();  // = T_body_cam by default
};

// The body pose in the MAVLink local frame.
Eigen::Isometry3d localBodyPose(const Eigen::Isometry3d& T_world_cam, const MavlinkFrameChange& frames);

// Aerospace ZYX Euler angles [roll, pitch, yaw] of R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d eulerRollPitchYaw(const Eigen::Matrix3d& R);

// J = d[x y z roll pitch yaw] / d delta at delta = 0 (see the header comment). Near pitch = +-90
// degrees the Euler rates are singular; check the covariance for finiteness.
Matrix6d mavlinkPoseJacobian(const Eigen::Isometry3d& T_world_cam, const MavlinkFrameChange& frames);

// Sigma_mav = J Sigma_delta J^T.
Matrix6d mavlinkPoseCovariance(const Matrix6d& covariance_delta, const Eigen::Isometry3d& T_world_cam,
                               const MavlinkFrameChange& frames);

// Covariance of the velocity MAVLink sends, [vx vy vz rollspeed pitchspeed yawspeed] in the body
// frame (docs/MAVLINK.md "Velocity covariance"), from the two poses it is differenced from and
// their covariances RELATIVE TO THE MAP (TrackResult::covariance_local; a map error common to both
// cancels in their difference), taken as independent:
//   e = Ad(T_cam_k_world T_cam_{k-1}_world^-1) d_{k-1} - d_k   (the relative camera motion's
//       right perturbation, Cov(e) = A L_{k-1} A^T + L_k; solver/pose_covariance.h)
//   eps = Ad(T_body_cam) e                                     (the same motion of the body)
//   d[v; w] = (1/dt) [I  [v dt]x; 0  I] eps                    (first order; per-frame rotation small)
Matrix6d mavlinkVelocityCovariance(const Matrix6d& local_covariance_previous, const Matrix6d& local_covariance,
                                   const Eigen::Isometry3d& T_world_cam_previous, const Eigen::Isometry3d& T_world_cam,
                                   double dt_s, const MavlinkFrameChange& frames);

// Row-major upper-right triangle (21 values: row 0 has 6, row 1 has 5, ...), as float.
void upperTriangle21(const Matrix6d& m, float out[21]);

}  // namespace plumb
