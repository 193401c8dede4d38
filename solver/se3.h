#pragma once
// SO(3) / SE(3) exponential and logarithm maps and THE perturbation convention of plumb's solver.
//
// Perturbation convention (used by every Jacobian, step and covariance in solver/):
//
//   poses are T_cam_world (world point -> camera point), perturbed on the LEFT:
//
//       T_cam_world  <-  expSE3(delta) * T_cam_world,     delta = [rho; phi] in R^6
//
//   rho (first three) is the translation part, phi (last three) the rotation part (axis * angle),
//   both expressed in the CAMERA frame. So for P_cam = T_cam_world * P_world,
//
//       d P_cam / d delta = [ I_3 | -[P_cam]x ]          (at delta = 0)
//
//   and a 6x6 pose covariance is the covariance of delta, i.e. of a small motion of the camera
//   frame, translation block first (rows 0-2), rotation block second (rows 3-5).
//
// expSE3([rho; phi]) = [ expSO3(phi)  V(phi) rho ; 0 1 ] with V the left Jacobian of SO(3), and
// logSE3 is its inverse. Small angles use Taylor series; angles near pi use the symmetric part of
// R so logSO3 stays accurate there.
#include "solver/types.h"

namespace plumb {

// Below this rotation angle [rad] the SO(3)/SE(3) coefficients lose digits and are taken from their
// Taylor series (se3.cpp, se3_jacobians.cpp: one threshold, so the maps and their Jacobians switch
// together).
inline constexpr double kSmallRotationAngle = 1e-4;
// Degrees per radian (180 / pi), for the angles tools print and grade.
inline constexpr double kDegreesPerRadian = 57.29577951308232;

// [v]x : the skew-symmetric matrix with hat(v) * w = v.cross(w).
Eigen::Matrix3d hat(const Eigen::Vector3d& v);

// Rodrigues: rotation by |phi| about phi / |phi|.
Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi);
// Inverse of expSO3 with |result| in [0, pi]. R must be a rotation matrix.
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);
// Left Jacobian of SO(3), V(phi) = sum_k [phi]x^k / (k+1)!.
Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& phi);

Eigen::Isometry3d expSE3(const Vector6d& rho_phi);
Vector6d logSE3(const Eigen::Isometry3d& T);

// The update used by every optimiser: returns expSE3(delta) * T_cam_world.
Eigen::Isometry3d applyLeftIncrement(const Vector6d& delta, const Eigen::Isometry3d& T_cam_world);

}  // namespace plumb
