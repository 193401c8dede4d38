#pragma once
// SE(3) adjoint and left Jacobians in plumb's [rho; phi] (translation first) tangent order, for
// residuals that are themselves logarithms of poses (the pose graph's relative-pose error).
//
//   Ad(T) = [ R  [t]x R ]        T expSE3(xi) T^-1 = expSE3(Ad(T) xi)
//           [ 0     R   ]
//
//   J_l(xi): expSE3(xi + d) = expSE3(J_l(xi) d) expSE3(xi) + O(|d|^2), so for a small left
//   increment x, logSE3(expSE3(x) expSE3(xi)) = xi + J_l(xi)^-1 x + O(|x|^2).
//
//   J_l([rho; phi]) = [ J(phi)  Q(rho, phi) ]     J_l^-1 = [ J^-1  -J^-1 Q J^-1 ]
//                     [   0       J(phi)    ]              [  0        J^-1     ]
//
// with J the left Jacobian of SO(3) (leftJacobianSO3 in se3.h) and Q Barfoot's coupling block
// (State Estimation for Robotics, eq. 7.86). The trigonometric coefficients use their Taylor series
// below 1e-2 rad, where the closed forms cancel catastrophically (Q's last one like 1/theta^4).
#include "solver/types.h"

namespace plumb {

Matrix6d adjointSE3(const Eigen::Isometry3d& T);

// Inverse of the left Jacobian of SO(3): I - [phi]x / 2 + (1/theta^2 - cot(theta/2)/(2 theta)) [phi]x^2.
// Finite for |phi| <= pi (what logSO3 returns).
Eigen::Matrix3d leftJacobianInverseSO3(const Eigen::Vector3d& phi);

Matrix6d leftJacobianSE3(const Vector6d& rho_phi);
Matrix6d leftJacobianInverseSE3(const Vector6d& rho_phi);  // closed form, not a numeric inverse

}  // namespace plumb
