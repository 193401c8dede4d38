#pragma once
// LoopContextCheck: does a loop correction leave the covisible landmarks of both sides better
// explained than before? (docs/LOOP.md "Do no harm"). The loop closer calls it after optimising the
// graph with a new loop edge, and rolls the loop back when the answer is no.
//
// Verification measured the loop from ONE pair of keyframes (query, candidate). Repeated furniture,
// identical modules or a window seen through the same mullions make that pair geometrically
// consistent at a wrong pose, and the odometry's uncertainty may be loose enough to find the jump
// plausible. The keyframes around each side are independent evidence: the query's predecessors
// and the candidate's graph neighbours usually see the same place too, including what is NOT
// repeated (the far wall, the door at the end of the room). For every pair (query-side keyframe i,
// candidate-side keyframe j), excluding the verified pair itself, the points of i are matched to
// those of j by descriptor (Hamming threshold, ratio test, both ways), and each match's
// reprojection error in j is computed with the graph's relative pose BEFORE the loop
// (T_j_world T_world_i of the graph as it was) and AFTER it (the optimised graph). The cost is
// sum min(e^2, tau^2) / sigma^2 over all matches: a match that no pose explains costs the same
// either way, a landmark pair that only one of the two geometries explains decides. A correct loop
// lowers it (it removes drift between the two sides); a wrong one raises it, because what the two
// sides really share stops projecting onto itself.
//
// The comparison uses image measurements only (pixels), not covariances, so it does not depend on
// how well the odometry or loop covariances are calibrated. Scratch is allocated in the
// constructor; evaluate() allocates nothing.
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>

#include "pipeline/loop/loop_keyframe.h"
#include "solver/camera_intrinsics.h"

namespace plumb::loop {

struct LoopContextCheckOptions {
  int query_neighbours = 2;      // the query's predecessors in the graph
  int candidate_neighbours = 2;  // on each side of the candidate
  int hamming_threshold = 50;
  float ratio = 0.8f;
  double pixel_sigma = 1.5;    // px
  double truncation_px = 8.0;  // a match farther than this costs the same whatever the pose
  // The loop is refused when cost_after > max_cost_ratio * cost_before: equal costs (no covisible
  // landmarks, or a correction too small to matter) pass; 2 % is the noise of the comparison
  // (correct loops with millimetre corrections land within +-0.1 %, wrong ones at 2-6x).
  double max_cost_ratio = 1.02;
};

struct LoopContextSide {
  const LoopCandidate* records[8] = {};
  Eigen::Isometry3d T_world_before[8];
  Eigen::Isometry3d T_world_after[8];
  int count = 0;
};

struct LoopContextResult {
  int pairs = 0;    // keyframe pairs compared
  int matches = 0;  // descriptor matches over those pairs
  int inliers_before = 0, inliers_after = 0;  // matches within 2 sigma
  double cost_before = 0, cost_after = 0;
};

class LoopContextCheck {
 public:
  LoopContextCheck(const CameraIntrinsics& camera, const LoopContextCheckOptions& options);
  ~LoopContextCheck();
  LoopContextCheck(const LoopContextCheck&) = delete;
  LoopContextCheck& operator=(const LoopContextCheck&) = delete;

  // Every pair (query side i, candidate side j) except (query.records[0], candidate.records[0]),
  // the pair verification measured.
  LoopContextResult evaluate(const LoopContextSide& query, const LoopContextSide& candidate);
  bool accepts(const LoopContextResult& r) const {
    return !(r.cost_after > options_.max_cost_ratio * r.cost_before);
  }
  const LoopContextCheckOptions& options() const { return options_; }
  static std::size_t scratchBytes();  // allocated by the constructor

 private:
  struct Scratch;
  CameraIntrinsics camera_;
  LoopContextCheckOptions options_;
  std::unique_ptr<Scratch> s_;
};

}  // namespace plumb::loop
