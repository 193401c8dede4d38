#pragma once
// Residuals of the three observation kinds with analytic Jacobians (paper eqs. 1-3, 7, 24, 29).
//
// All poses are T_cam_world with the left perturbation of solver/se3.h:
//   P_cam = R P_world + t,   dP_cam/d delta = [ I | -[P_cam]x ],   dP_cam/dP_world = R.
// Residual sign is prediction - measurement (paper eq. 7): e = pi(T P) - z.
//
//   kind           residual                      z                 rows
//   stereo point   [u, v, u - bf/Z] - z          [u, v, u_r]        3
//   mono point     [u, v] - z                    [u, v]             2
//   line sample    l^T [u, v, 1]                 l = [a, b, c]      1   (l / sqrt(a^2 + b^2))
//
// The evaluate* functions return false (and leave outputs untouched) when the point is not in
// front of the camera (Z < min_depth): such a residual is undefined, and callers treat it as an
// outlier for this linearisation instead of producing Inf/NaN.
// Jacobian pointers may be null when only the residual is needed.
#include "solver/camera_intrinsics.h"
#include "solver/types.h"

namespace plumb {

// Points closer than this to the camera plane [m] are rejected by the factors.
constexpr double kFactorMinDepth = 1e-6;

// d[u, v, u_r] / d P_cam at P_cam (Z > 0). Row 2 is the virtual right camera.
inline Eigen::Matrix3d stereoProjectionJacobian(const CameraIntrinsics& camera,
                                                const Eigen::Vector3d& P_cam) {
  const double inv_z = 1.0 / P_cam.z();
  const double inv_z2 = inv_z * inv_z;
  Eigen::Matrix3d J;
  J << camera.fx * inv_z, 0.0, -camera.fx * P_cam.x() * inv_z2,  //
      0.0, camera.fy * inv_z, -camera.fy * P_cam.y() * inv_z2,   //
      camera.fx * inv_z, 0.0, (-camera.fx * P_cam.x() + camera.bf) * inv_z2;
  return J;
}

// [u, v] of a camera-frame point.
inline Eigen::Vector2d projectToPixel(const CameraIntrinsics& camera, const Eigen::Vector3d& P_cam) {
  const double inv_z = 1.0 / P_cam.z();
  return {camera.fx * P_cam.x() * inv_z + camera.cx, camera.fy * P_cam.y() * inv_z + camera.cy};
}

// d P_cam / d delta for the left perturbation: [ I | -[P_cam]x ].
inline Matrix36d pointPoseJacobian(const Eigen::Vector3d& P_cam) {
  Matrix36d J;
  J << 1.0, 0.0, 0.0, 0.0, P_cam.z(), -P_cam.y(),  //
      0.0, 1.0, 0.0, -P_cam.z(), 0.0, P_cam.x(),   //
      0.0, 0.0, 1.0, P_cam.y(), -P_cam.x(), 0.0;
  return J;
}

// Stereo (RGB-D) point: residual [u, v, u_r] - z_uvr.
inline bool evaluateStereoPoint(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                                const Eigen::Vector3d& P_world, const Eigen::Vector3d& z_uvr,
                                Eigen::Vector3d* residual, Matrix36d* J_pose, Eigen::Matrix3d* J_point) {
  const Eigen::Vector3d P_cam = T_cam_world * P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return false;
  const Eigen::Vector2d uv = projectToPixel(camera, P_cam);
  *residual = Eigen::Vector3d(uv.x(), uv.y(), uv.x() - camera.bf / P_cam.z()) - z_uvr;
  if (J_pose != nullptr || J_point != nullptr) {
    const Eigen::Matrix3d J_proj = stereoProjectionJacobian(camera, P_cam);
    if (J_pose != nullptr) *J_pose = J_proj * pointPoseJacobian(P_cam);
    if (J_point != nullptr) J_point->noalias() = J_proj * T_cam_world.linear();
  }
  return true;
}

// Monocular point: residual [u, v] - z_uv.
inline bool evaluateMonoPoint(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                              const Eigen::Vector3d& P_world, const Eigen::Vector2d& z_uv,
                              Eigen::Vector2d* residual, Matrix26d* J_pose, Matrix23d* J_point) {
  const Eigen::Vector3d P_cam = T_cam_world * P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return false;
  *residual = projectToPixel(camera, P_cam) - z_uv;
  if (J_pose != nullptr || J_point != nullptr) {
    const Matrix23d J_proj = stereoProjectionJacobian(camera, P_cam).topRows<2>();
    if (J_pose != nullptr) *J_pose = J_proj * pointPoseJacobian(P_cam);
    if (J_point != nullptr) J_point->noalias() = J_proj * T_cam_world.linear();
  }
  return true;
}

// Line-guidance sample: signed pixel distance of pi(T P) to the normalised observed line l.
inline bool evaluateLineSample(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                               const Eigen::Vector3d& P_world, const Eigen::Vector3d& line,
                               double* residual, RowVector6d* J_pose, Eigen::RowVector3d* J_point) {
  const Eigen::Vector3d P_cam = T_cam_world * P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return false;
  const Eigen::Vector2d uv = projectToPixel(camera, P_cam);
  *residual = line.x() * uv.x() + line.y() * uv.y() + line.z();
  if (J_pose != nullptr || J_point != nullptr) {
    const Eigen::RowVector3d J_proj =
        line.head<2>().transpose() * stereoProjectionJacobian(camera, P_cam).topRows<2>();
    if (J_pose != nullptr) *J_pose = J_proj * pointPoseJacobian(P_cam);
    if (J_point != nullptr) *J_point = J_proj * T_cam_world.linear();
  }
  return true;
}

// Normalises a 2D line [a, b, c] so that l^T [u v 1] is a signed distance in pixels.
// Returns false for a degenerate line (a = b = 0).
inline bool normalizeLine(const Eigen::Vector3d& line_abc, Eigen::Vector3d* line_normalized) {
  const double norm = line_abc.head<2>().norm();
  if (!(norm > 0.0)) return false;
  *line_normalized = line_abc / norm;
  return true;
}

}  // namespace plumb
