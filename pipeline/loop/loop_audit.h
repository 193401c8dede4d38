#pragma once
// LoopAudit: what loop closing decided about every candidate that reached verification, kept so
// that a run can be graded against ground truth afterwards (`plumb run --stats` writes it,
// `plumb eval --gt GT --loops STATS.json` grades it; docs/LOOP.md "Loop audit").
//
// Fixed-size storage: both lists are reserved in the constructor (capacities below) and never
// grow; entries past the capacity are counted (`entries_dropped`, `keyframes_dropped`), not kept.
// Recording an entry is a copy into reserved memory: no allocation on the loop stage's path.
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "pipeline/loop/loop_verifier.h"
#include "solver/types.h"

namespace plumb::loop {

// One verified candidate. Counts are as far as verification got (0 beyond the stage that
// rejected it); the implied correction and chi-square are NaN when plausibility was not reached.
struct LoopAuditEntry {
  uint32_t query_id = 0;
  uint32_t candidate_id = 0;
  double query_timestamp_s = 0;
  double candidate_timestamp_s = 0;  // 0 for a keyframe loaded from a map file (not stored there)
  float place_score = 0;             // KeyframeDatabase score of the candidate
  int matches = 0;                   // ORB matches
  int ransac_inliers = 0;
  int point_inliers = 0;        // after refinement
  int line_matches = 0;         // LBD matches whose samples entered the refinement
  int line_sample_inliers = 0;  // line-guidance samples inlying after refinement
  int unreliable_features = 0;  // features taken out of the refinement for their leverage
  double max_leverage = 0;      // largest feature leverage of the final refinement (0: not reached)
  double correction_m = 0;      // the correction the loop implies at the query keyframe
  double correction_deg = 0;
  double chi2 = 0;              // plausibility chi-square (6 dof)
  LoopRejection outcome = LoopRejection::kFewMatches;  // kNone: accepted
  // The do-no-harm check of an accepted loop (loop_context_check.h): descriptor matches between
  // the keyframes around both sides and their reprojection cost before / after the correction.
  int context_matches = 0;
  double context_cost_before = 0;
  double context_cost_after = 0;
  // The loop constraint (pose of the query camera in the candidate camera) and the covariance the
  // pose graph weighs it with (left perturbation of T_query_candidate, [rho; phi]); identity /
  // zero when verification did not produce one.
  Eigen::Isometry3d T_candidate_query = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();
};

struct LoopAuditKeyframe {
  uint32_t id = 0;
  double timestamp_s = 0;
};

class LoopAudit {
 public:
  static constexpr std::size_t kDefaultMaxEntries = 512;
  static constexpr std::size_t kDefaultMaxKeyframes = 4096;

  explicit LoopAudit(std::size_t max_entries = kDefaultMaxEntries,
                     std::size_t max_keyframes = kDefaultMaxKeyframes);

  // Returns the stored entry (to be completed by later stages) or nullptr when full (counted).
  LoopAuditEntry* add(const LoopAuditEntry& entry);
  void addKeyframe(uint32_t id, double timestamp_s);

  const std::vector<LoopAuditEntry>& entries() const { return entries_; }
  const std::vector<LoopAuditKeyframe>& keyframes() const { return keyframes_; }
  uint64_t entriesDropped() const { return entries_dropped_; }
  uint64_t keyframesDropped() const { return keyframes_dropped_; }
  std::size_t memoryBytes() const {
    return entries_.capacity() * sizeof(LoopAuditEntry) + keyframes_.capacity() * sizeof(LoopAuditKeyframe);
  }

 private:
  std::vector<LoopAuditEntry> entries_;
  std::vector<LoopAuditKeyframe> keyframes_;
  uint64_t entries_dropped_ = 0;
  uint64_t keyframes_dropped_ = 0;
};

}  // namespace plumb::loop
