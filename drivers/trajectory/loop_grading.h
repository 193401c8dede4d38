#pragma once
// Grading a run's loop audit (the "loop_audit" member of `plumb run --stats`, docs/LOOP.md "Loop
// audit") against ground truth: `plumb eval --gt GT --loops STATS.json`.
//
// Per ACCEPTED loop: the error of its constraint Z = T_candidate_query against the ground-truth
// relative pose G_c^-1 G_q, as e = log(G_q^-1 G_c Z) (a left perturbation of T_query_candidate,
// the convention of the covariance the audit stores): translation |t| in m, rotation angle in deg,
// and the Mahalanobis distance sqrt(e^T S^-1 e) in sigmas of the constraint's own covariance S;
// also the true baseline between the two keyframes (m, deg), which the error is studied against.
// A loop is CORRECT when its error is within 5 cm AND 2 deg AND e^T S^-1 e <= 20.06 (the 6-dof
// chi-square with the probability of a 1-D 3-sigma interval, 99.73 %). Precision = correct /
// accepted.
//
// REVISITS (what recall is measured over), from the ground truth and the audit's keyframe list:
//   - a keyframe q is a REVISIT KEYFRAME when the ground-truth camera, at some time no later than
//     the newest keyframe at least `min_age_keyframes` ids older than q (the loop closer's own
//     bound: nothing younger may be a candidate), was at most `revisit_distance_m` from q and
//     looked in a direction at most `revisit_angle_deg` away (angle between the optical axes);
//   - consecutive revisit keyframes (in id order, no non-revisit keyframe between them) form a
//     REVISIT, cut into pieces of at most `revisit_span_s` seconds so that a long return (a whole
//     second lap) counts as several places revisited, not one;
//   - a revisit is RECALLED when a correct accepted loop has its query keyframe in it.
// Recall = recalled revisits / revisits. Keyframes whose time has no ground truth are skipped.
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "drivers/trajectory/trajectory_io.h"
#include "platform/status.h"
#include "solver/types.h"

namespace plumb {

struct AuditedLoop {
  uint32_t query_id = 0, candidate_id = 0;
  double query_t = 0, candidate_t = 0;
  std::string outcome;  // "accepted" or the rejection reason
  bool has_constraint = false;
  Eigen::Isometry3d T_candidate_query = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();
};

struct LoopAuditFile {
  std::vector<std::pair<uint32_t, double>> keyframes;  // id, timestamp
  std::vector<AuditedLoop> candidates;
};

// Reads the "loop_audit" member of a `plumb run --stats` JSON file. Errors name the file and what
// is missing (a run with --no-loops has no audit).
Status readLoopAudit(const std::string& stats_path, LoopAuditFile* out);

struct LoopGradingOptions {
  double max_error_m = 0.05;
  double max_error_deg = 2.0;
  double max_chi2 = 20.06;  // 6 dof, 99.73 %
  int min_age_keyframes = 33;  // the loop closer's (LoopCloserOptions::min_age_keyframes)
  double revisit_distance_m = 0.3;
  double revisit_angle_deg = 20.0;
  double revisit_span_s = 3.0;
  double max_gt_gap_s = 0.1;  // ground truth is interpolated between samples at most this far apart
};

struct GradedLoop {
  uint32_t query_id = 0, candidate_id = 0;
  double query_t = 0, candidate_t = 0;
  bool has_ground_truth = false;
  double error_m = 0, error_deg = 0, error_sigmas = 0;
  // How far apart the two views truly are (G_c^-1 G_q): a loop's error grows with its baseline,
  // which its covariance must follow (docs/LOOP.md "Loop error against baseline").
  double baseline_m = 0, baseline_deg = 0;
  bool correct = false;
};

struct LoopGrading {
  std::size_t verified = 0;  // candidates in the audit
  std::size_t accepted = 0;
  std::size_t graded = 0;  // accepted with ground truth at both ends
  std::size_t correct = 0;
  std::size_t within_distance = 0;  // within 5 cm and 2 deg whatever their covariance says
  std::vector<GradedLoop> loops;  // the accepted ones
  std::size_t revisit_keyframes = 0;
  std::size_t revisits = 0;
  std::size_t revisits_recalled = 0;
  double precision() const { return graded ? double(correct) / double(graded) : 1.0; }
  double recall() const { return revisits ? double(revisits_recalled) / double(revisits) : 1.0; }
};

// Ground truth at time t: interpolated between the two samples around t (linear position,
// slerp rotation) when they are at most max_gap_s apart, or a sample within 0.02 s; false if none.
bool groundTruthAt(const std::vector<StampedPose>& ground_truth, double t, double max_gap_s,
                   Eigen::Isometry3d* T_world_cam);

// ground_truth sorted by time (readTumTrajectory's order).
LoopGrading gradeLoops(const std::vector<StampedPose>& ground_truth, const LoopAuditFile& audit,
                       const LoopGradingOptions& options);

}  // namespace plumb
