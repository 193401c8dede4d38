#pragma once
// Leverage of a group of observations in a pose-only solution (solver/pose_optimizer.h): how much
// of the pose's information in its best-determined direction comes from that group alone.
//
// With C = H^-1 the solution's covariance and H_g = sum over the group of J_i^T (w_i Omega_i) J_i
// (the same IRLS-weighted information the optimiser summed into H), the leverage is
//   h_g = lambda_max(C^1/2 H_g C^1/2)  in [0, 1]
// (the largest eigenvalue of the group's block of the hat matrix). Adjustment theory calls 1 - h
// the group's redundancy: an error in the group shows in its own residuals only scaled by (1 - h),
// because the pose moves to absorb the rest. So an error the inlier gate cannot see (a residual
// up to k whitened units) can move the pose by up to k sqrt(h / (1 - h)) of its own sigma
// (Baarda's external reliability): beyond h = 0.5 that is more than the gate itself, i.e. the
// solution's covariance no longer bounds what one unchecked feature does to it.
//
// Allocation-free, deterministic.
#include "solver/camera_intrinsics.h"
#include "solver/pose_optimizer.h"
#include "solver/types.h"

namespace plumb {

// w J^T Omega J of one observation at T_cam_world (w: the optimiser's IRLS weight for it with
// `options`' kernel); zero when the point is behind the camera.
Matrix6d poseInformation(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                         const PosePointObservation& obs, const PoseOptimizerOptions& options);
Matrix6d poseInformation(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                         const PoseLineObservation& obs, const PoseOptimizerOptions& options);

// lambda_max(C^1/2 H_group C^1/2) for the solution covariance C (symmetric positive definite);
// 1 when C is not (no direction is determined by anything else).
double groupLeverage(const Matrix6d& covariance, const Matrix6d& group_information);

}  // namespace plumb
