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

// ---- Camera-frame residuals: e and d e / d P_cam at P_cam (caller checks Z > kFactorMinDepth).
// The optimisers use these directly (pose-only works in point space, see pose_optimizer.cpp).

inline void stereoResidualAt(const CameraIntrinsics& camera, const Eigen::Vector3d& P_cam,
                             const Eigen::Vector3d& z_uvr, Eigen::Vector3d* e, Eigen::Matrix3d* J_cam) {
  const double inv_z = 1.0 / P_cam.z();
  const double u = camera.fx * P_cam.x() * inv_z + camera.cx;
  const double v = camera.fy * P_cam.y() * inv_z + camera.cy;
  *e = Eigen::Vector3d(u - z_uvr.x(), v - z_uvr.y(), u - camera.bf * inv_z - z_uvr.z());
  if (J_cam == nullptr) return;
  const double fx_z = camera.fx * inv_z;
  const double fy_z = camera.fy * inv_z;
  const double du_dz = -fx_z * P_cam.x() * inv_z;
  *J_cam << fx_z, 0.0, du_dz,                    //
      0.0, fy_z, -fy_z * P_cam.y() * inv_z,      //
      fx_z, 0.0, du_dz + camera.bf * inv_z * inv_z;
}

inline void monoResidualAt(const CameraIntrinsics& camera, const Eigen::Vector3d& P_cam,
                           const Eigen::Vector2d& z_uv, Eigen::Vector2d* e, Matrix23d* J_cam) {
  const double inv_z = 1.0 / P_cam.z();
  const double fx_z = camera.fx * inv_z;
  const double fy_z = camera.fy * inv_z;
  *e = Eigen::Vector2d(fx_z * P_cam.x() + camera.cx - z_uv.x(), fy_z * P_cam.y() + camera.cy - z_uv.y());
  if (J_cam == nullptr) return;
  *J_cam << fx_z, 0.0, -fx_z * P_cam.x() * inv_z,  //
      0.0, fy_z, -fy_z * P_cam.y() * inv_z;
}

inline void lineResidualAt(const CameraIntrinsics& camera, const Eigen::Vector3d& P_cam,
                           const Eigen::Vector3d& line, double* e, Eigen::RowVector3d* J_cam) {
  const double inv_z = 1.0 / P_cam.z();
  const double a_fx_z = line.x() * camera.fx * inv_z;  // d e / d X
  const double b_fy_z = line.y() * camera.fy * inv_z;  // d e / d Y
  *e = a_fx_z * P_cam.x() + b_fy_z * P_cam.y() + line.x() * camera.cx + line.y() * camera.cy + line.z();
  if (J_cam == nullptr) return;
  *J_cam << a_fx_z, b_fy_z, -(a_fx_z * P_cam.x() + b_fy_z * P_cam.y()) * inv_z;
}

// d e / d delta = J_cam [ I | -[P_cam]x ]. Row r of J_cam [P_cam]x is (r x P_cam)^T, so the
// rotation block is (P_cam x r)^T: three cross products instead of a 3x3 product.
template <int R>
inline Eigen::Matrix<double, R, 6> liftToPose(const Eigen::Matrix<double, R, 3>& J_cam, const Eigen::Vector3d& P_cam) {
  Eigen::Matrix<double, R, 6> J;
  J.template leftCols<3>() = J_cam;
  for (int r = 0; r < R; ++r) {
    const Eigen::Vector3d row = J_cam.row(r).transpose();
    J.template block<1, 3>(r, 3) = P_cam.cross(row).transpose();
  }
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

// ---- World-frame factors: residual and Jacobians wrt the pose (6) and the world point (3).

// Stereo (RGB-D) point: residual [u, v, u_r] - z_uvr.
inline bool evaluateStereoPoint(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                                const Eigen::Vector3d& P_world, const Eigen::Vector3d& z_uvr,
                                Eigen::Vector3d* residual, Matrix36d* J_pose, Eigen::Matrix3d* J_point) {
  const Eigen::Vector3d P_cam = T_cam_world * P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return false;
  const bool want_jacobians = J_pose != nullptr || J_point != nullptr;
  Eigen::Matrix3d J_cam;
  stereoResidualAt(camera, P_cam, z_uvr, residual, want_jacobians ? &J_cam : nullptr);
  if (J_pose != nullptr) *J_pose = liftToPose<3>(J_cam, P_cam);
  if (J_point != nullptr) J_point->noalias() = J_cam * T_cam_world.linear();
  return true;
}

// Monocular point: residual [u, v] - z_uv.
inline bool evaluateMonoPoint(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                              const Eigen::Vector3d& P_world, const Eigen::Vector2d& z_uv,
                              Eigen::Vector2d* residual, Matrix26d* J_pose, Matrix23d* J_point) {
  const Eigen::Vector3d P_cam = T_cam_world * P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return false;
  const bool want_jacobians = J_pose != nullptr || J_point != nullptr;
  Matrix23d J_cam;
  monoResidualAt(camera, P_cam, z_uv, residual, want_jacobians ? &J_cam : nullptr);
  if (J_pose != nullptr) *J_pose = liftToPose<2>(J_cam, P_cam);
  if (J_point != nullptr) J_point->noalias() = J_cam * T_cam_world.linear();
  return true;
}

// Line-guidance sample: signed pixel distance of pi(T P) to the normalised observed line l.
inline bool evaluateLineSample(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                               const Eigen::Vector3d& P_world, const Eigen::Vector3d& line,
                               double* residual, RowVector6d* J_pose, Eigen::RowVector3d* J_point) {
  const Eigen::Vector3d P_cam = T_cam_world * P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return false;
  const bool want_jacobians = J_pose != nullptr || J_point != nullptr;
  Eigen::RowVector3d J_cam;
  lineResidualAt(camera, P_cam, line, residual, want_jacobians ? &J_cam : nullptr);
  if (J_pose != nullptr) *J_pose = liftToPose<1>(J_cam, P_cam);
  if (J_point != nullptr) J_point->noalias() = J_cam * T_cam_world.linear();
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
