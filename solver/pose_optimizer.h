#pragma once
// Pose-only optimisation (motion-only BA) for tracking: refine T_cam_world against map points and
// line-guidance samples whose world positions are held fixed.
//
// Cost: 0.5 * sum_i rho_i(e_i^T Omega_i e_i) over the observations currently classed inliers,
// with the factors of solver/factors.h and the kernels of solver/robust_kernel.h.
// Like ORB-SLAM2's PoseOptimization it runs `rounds` rounds of up to `iterations_per_round`
// Gauss-Newton (or Levenberg-Marquardt) iterations; after each round EVERY observation is
// re-classified by its chi-square value against the threshold of its dimension (3 dof stereo
// points, 2 dof mono points, 1 dof line samples), so a wrongly rejected match can come back.
// A round stops early once the step is below `step_tolerance`, and the rounds stop early once a
// classification leaves every flag unchanged (the next round would repeat the last one). A round
// after a converged one starts from the last linearisation with only the re-classified
// observations added or removed (at that linearisation's pose, within the tolerance of the
// round's end), not from a new linearisation of every observation.
//
// Covariance: at the solution, the inverse of H = sum_inliers J_i^T (w_i Omega_i) J_i (w_i the
// IRLS weight rho'(s_i)), the 6x6 covariance of the left perturbation delta = [rho; phi] of
// solver/se3.h. `covariance_valid` is false when H is not positive definite (too few inliers,
// degenerate geometry).
//
// Map error: pose-only holds the landmarks exact, but a landmark's position carries the errors of
// the measurements it was made from. With `map_share` s_i per observation (the landmark's error,
// seen in this observation's residual, taken as s_i times this measurement's covariance: 1/n for
// a landmark averaged from n measurements like this one), `map_covariance` = C (sum_inliers s_i
// J_i^T (w_i Omega_i) J_i) C is the pose error the landmark errors cause (first order, landmarks
// independent of each other). It does not change the estimate.
//
// No heap allocation: inputs are caller arrays, inlier flags are written into caller buffers.
#include <cmath>

#include "solver/outlier_thresholds.h"
#include "solver/camera_intrinsics.h"
#include "solver/robust_kernel.h"
#include "solver/types.h"
#include "solver/variance_factor.h"

namespace plumb {

struct PoseOptimizerOptions {
  RobustKernelType kernel = RobustKernelType::kPseudoHuber;
  // Kernel widths per residual dimension, in whitened units: sqrt of the 95% chi-square quantile,
  // ORB-SLAM2's choice, so inliers are (almost) unaffected by the kernel.
  double kernel_delta_stereo = std::sqrt(7.815);
  double kernel_delta_mono = std::sqrt(5.991);
  double kernel_delta_line = std::sqrt(3.841);
  // Chi-square thresholds (95%) separating inliers from outliers between rounds.
  OutlierChi2 chi2;  // outlier thresholds by error dof (solver/outlier_thresholds.h)
  int rounds = 4;                // ORB-SLAM2 uses 4 rounds ...
  int iterations_per_round = 10;  // ... of 10 iterations
  // Stop a round when |delta| (translation in m and rotation in rad together) is below this:
  // 1e-6 (1 micrometre / microradian) is far below what RGB-D measurements can resolve.
  double step_tolerance = 1e-6;
  // false: Gauss-Newton (steps always taken). true: Levenberg-Marquardt with lambda adapted to
  // the step quality (safer from poor initial poses, a little slower).
  bool levenberg_marquardt = false;
  double initial_lambda = 1e-4;  // LM only: relative to the diagonal of H
  // false: skip the last linearisation at the final pose, so PoseResult's covariance stays
  // invalid and final_cost 0 (for a caller that only wants the pose and the inlier flags).
  bool compute_covariance = true;
};

// A map point seen by the current frame. With has_depth = false only z.head<2>() = [u, v] and
// information.topLeftCorner<2,2>() are used.
struct PosePointObservation {
  Eigen::Vector3d P_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d z = Eigen::Vector3d::Zero();  // [u, v, u_r]
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
  bool has_depth = true;
  double map_share = 0.0;  // landmark error / measurement covariance (see the top); 0 = exact
};

// A line-guidance sample: world point P that should project onto the normalised observed line.
struct PoseLineObservation {
  Eigen::Vector3d P_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d line = Eigen::Vector3d(1.0, 0.0, 0.0);  // [a, b, c], a^2 + b^2 = 1
  double information = 1.0;
  double map_share = 0.0;  // as for points
};

struct PoseResult {
  Eigen::Isometry3d T_cam_world = Eigen::Isometry3d::Identity();
  int num_point_inliers = 0;
  int num_line_inliers = 0;
  int iterations = 0;        // total over rounds
  double initial_cost = 0.0;  // robust cost of all observations at the initial pose
  double final_cost = 0.0;    // robust cost of the final inliers at the final pose
  Matrix6d covariance = Matrix6d::Zero();
  bool covariance_valid = false;
  Matrix6d map_covariance = Matrix6d::Zero();  // valid with covariance_valid (see the top)
  // chi2 of the final inliers at the final pose (the last classification), for the a posteriori
  // variance factor (solver/variance_factor.h; redundancy: their error dof - 6).
  InlierChi2Sums inlier_chi2;
};

// Inlier flags: point_inliers[i] / line_inliers[i] are written for every observation (arrays of
// num_points / num_lines entries; either may be null when its count is 0).
PoseResult optimizePose(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world_initial,
                        const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
                        int num_lines, const PoseOptimizerOptions& options, bool* point_inliers,
                        bool* line_inliers);

}  // namespace plumb
