#pragma once
// NEES (normalised estimation error squared) of the covariances plumb publishes, against ground
// truth (docs/UNCERTAINTY.md). For an error e of d degrees of freedom drawn from the covariance C
// that claims to describe it, NEES = e^T C^-1 e has mean d and lies below the 95% chi-square
// quantile 95% of the time; mean NEES / d is 1 for a calibrated covariance, above 1 for an
// overconfident one.
//
// Quantities, each compared where ground truth can check it without a gauge choice of its own:
//  - keyframe_relative: the relative pose between consecutive keyframes, T_prev_this, and its
//    covariance from local BA's joint marginal (the 51-field keyframe covariance lines). Error
//    e = log(T_prev_this(gt)^-1 T_prev_this(est)): gauge-free, no alignment.
//  - tracked_world: each tracked pose with its world covariance (the tracked covariance file: what
//    MAVLink sends). The estimator's gauge is its world frame, the camera at initialisation:
//    ground truth is expressed in it through the first pose of the estimate (`anchor`), i.e.
//    G'(t) = T_est(t0) G(t0)^-1 G(t), and e = log(T_cam_world(est) T_cam_world(G')^-1) (the left
//    perturbation of solver/se3.h). No least-squares alignment: that would hide drift the
//    covariance has to describe.
//  - frame_motion: consecutive tracked frames (within max_frame_gap_s), the relative pose and the
//    sum of the two frames' local covariances (what the MAVLink velocity covariance is, times dt^2).
// Ground truth is interpolated at each timestamp (linear position, slerp rotation) between its two
// neighbouring samples, at most max_gt_gap_s apart; a stamp outside is skipped (counted).
#include <cstddef>
#include <vector>

#include "drivers/trajectory/covariance_io.h"
#include "platform/status.h"
#include "sensor/stamped_pose.h"

namespace plumb {

struct NeesOptions {
  double max_gt_gap_s = 0.05;       // ground-truth neighbours further apart: no truth at that stamp
  double max_frame_gap_s = 0.1;     // frame_motion: consecutive tracked frames at most this apart
};

// Statistics of one quantity. 6 dof; the translation and rotation blocks alone (3 dof each) say
// which part is off.
struct NeesStatistics {
  std::size_t count = 0;
  std::size_t skipped_no_truth = 0;  // stamps ground truth does not cover
  double mean_per_dof = 0;           // mean NEES / 6
  double median_per_dof = 0;
  double translation_mean_per_dof = 0;  // mean of e_t^T C_tt^-1 e_t / 3
  double rotation_mean_per_dof = 0;
  double inside_95 = 0;  // share of NEES <= chi2_6(0.95) = 12.592
  double rmse_translation_m = 0, rmse_rotation_deg = 0;      // of the errors
  double rms_sigma_translation_m = 0, rms_sigma_rotation_deg = 0;  // what the covariances claim
};

struct NeesResult {
  NeesStatistics keyframe_relative;
  NeesStatistics tracked_world;
  NeesStatistics frame_motion;
};

// Ground-truth pose at `t` by interpolation; false outside the ground truth or across a gap.
bool interpolatePose(const std::vector<StampedPose>& ground_truth, double t, double max_gap_s,
                     Eigen::Isometry3d* T_world_cam);

// `anchor`: the estimate's first valid pose (tracked_world's gauge); unused for keyframe files.
// Quantities without lines in `file` stay at count 0. Error: ground truth empty or unsorted.
Status evaluateNees(const std::vector<StampedPose>& ground_truth, const CovarianceFile& file,
                    const StampedPose& anchor, const NeesOptions& options, NeesResult* out);

}  // namespace plumb
