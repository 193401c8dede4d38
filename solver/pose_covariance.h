#pragma once
// Covariance algebra of poses in plumb's convention (solver/se3.h: T_cam_world perturbed on the
// left, delta = [rho; phi]), for what the system PUBLISHES: relative poses between keyframes from
// local BA's joint marginal, poses chained from those, and the motion between two frames.
//
// RELATIVE POSE. T_i_j = T_cam_i_world * T_cam_j_world^-1 (camera j in camera i: the pose graph's
// edge measurement, solver/pose_graph.h). With T_i <- exp(d_i) T_i and T_j <- exp(d_j) T_j,
//
//   exp(d_i) T_i T_j^-1 exp(-d_j) = T_i_j exp(Ad(T_j_i) d_i) exp(-d_j) ~ T_i_j exp(e),
//   e = A d_i - d_j,   A = Ad(T_j_i) = Ad(T_cam_j_world T_cam_i_world^-1),
//   Cov(e) = A C_ii A^T + C_jj - A C_ij - C_ji A^T
//
// e is a right perturbation of T_i_j (a motion of camera j in its own frame), exactly the pose
// graph's edge error, so Cov(e)^-1 is that edge's information. C_ij is the cross block of the
// joint covariance of (d_i, d_j) (LocalBundleAdjuster::fullCovariance()); a fixed keyframe has
// C_ii = C_ij = 0. The gauge (the fixed keyframes) cancels in e: this is a quantity ground truth
// can check without any alignment.
//
// CHAINING. T_j = T_j_i T_i with T_j_i = T_i_j^-1 = exp(-e) T_j_i(true), so
//   d_j = Ad(T_j_i) d_i - e,   Cov(d_j) = Ad(T_j_i) Cov(d_i) Ad(T_j_i)^T + Cov(e)
// when e is independent of d_i (successive relative poses from different measurements).
#include "solver/types.h"

namespace plumb {

// Cov(e) above. T_i, T_j: T_cam_world of the two poses; C_ii, C_jj their marginal blocks, C_ij the
// cross block (rows of d_i, columns of d_j). The result is symmetrised.
Matrix6d relativePoseCovariance(const Eigen::Isometry3d& T_i_cam_world, const Eigen::Isometry3d& T_j_cam_world,
                                const Matrix6d& C_ii, const Matrix6d& C_jj, const Matrix6d& C_ij);

// Cov(d_j) of CHAINING: the covariance of T_j = T_j_i T_i, given Cov(d_i) (left perturbation of T_i)
// and Cov(e) of the right perturbation of T_i_j, assumed independent.
Matrix6d chainPoseCovariance(const Eigen::Isometry3d& T_i_cam_world, const Eigen::Isometry3d& T_j_cam_world,
                             const Matrix6d& covariance_i, const Matrix6d& relative_covariance);

// The right perturbation e of T_i_j = T_i T_j^-1 between estimate and truth:
// e = logSE3(T_i_j(true)^-1 T_i_j(estimate)). NEES = e^T Cov(e)^-1 e.
Vector6d relativePoseError(const Eigen::Isometry3d& T_i_j_true, const Eigen::Isometry3d& T_i_j_estimate);

// True when the largest translation and rotation sigmas of a [rho phi] covariance (square roots of
// the largest eigenvalues of its two diagonal 3x3 blocks, read as symmetric) are within the bounds.
bool poseSigmasWithin(const Matrix6d& covariance, double max_translation_sigma, double max_rotation_sigma);

// True when `covariance` of a [rho phi] pose perturbation can be published: finite, symmetric
// positive definite (Cholesky of its symmetric part), and poseSigmasWithin the bounds.
bool publishablePoseCovariance(const Matrix6d& covariance, double max_translation_sigma, double max_rotation_sigma);

// Normalised estimation error squared e^T C^-1 e (C symmetric positive definite); NaN when C is not.
double normalizedErrorSquared(const Vector6d& error, const Matrix6d& covariance);

}  // namespace plumb
