#pragma once
// Trajectory evaluation by the TUM RGB-D benchmark's conventions.
//
// ATE (evaluate_ate.py): associate estimate and ground truth stamps (greedy unique pairs by
// smallest |dt|, |dt| < 0.02 s), align the estimate's positions to the ground truth's with a rigid
// transform (no scale), report statistics of the remaining translational differences.
//
// RPE (evaluate_rpe.py with --fixed_delta --delta 1 --delta_unit s): for each estimate frame i,
// j = the estimate frame whose stamp is closest to t_i + delta (pairs where j is the last frame are
// skipped, as the benchmark does); both ends are matched to the closest ground-truth stamp, which
// must lie within 2x the median ground-truth interval. Error E = (E_i^-1 E_j) (G_i^-1 G_j)^-1;
// translation |t(E)| and rotation angle(E) over that ~1 s interval, reported per second (m/s and
// deg/s), not divided by the exact interval (the benchmark's convention).
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "drivers/common/timestamp_association.h"
#include "drivers/trajectory/trajectory_io.h"
#include "platform/status.h"

namespace plumb {

struct ErrorStatistics {
  double rmse = 0, mean = 0, median = 0, min = 0, max = 0;
};

struct AteOptions {
  AssociationOptions association;  // |dt| < 0.02 s, no offset
};

// One associated pair after alignment (for plots).
struct AteSample {
  double timestamp_s = 0;               // the ground truth's stamp
  Eigen::Vector3d p_world_gt;           // ground-truth camera position
  Eigen::Vector3d p_world_est_aligned;  // estimate position mapped by T_gt_est
};

struct AteResult {
  std::size_t pairs = 0;
  ErrorStatistics translation_m;
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();  // aligns estimate world to gt world
  std::vector<AteSample> samples;                              // sorted by time
};

// Invalid (lost) poses are ignored. Error if fewer than 3 pairs associate.
Status evaluateAte(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimate,
                   const AteOptions& options, AteResult* out);

struct RpeOptions {
  double delta_s = 1.0;  // interval of the relative motion (benchmark: 1 s)
};

struct RpeResult {
  std::size_t pairs = 0;
  ErrorStatistics translation_m_per_s;
  ErrorStatistics rotation_deg_per_s;
};

// Error if no pair survives (estimate shorter than delta, or no ground truth near it).
Status evaluateRpe(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimate,
                   const RpeOptions& options, RpeResult* out);

// Statistics of a list of non-negative errors (copy sorted for the median). Empty -> zeros.
ErrorStatistics computeErrorStatistics(const std::vector<double>& errors);

}  // namespace plumb
