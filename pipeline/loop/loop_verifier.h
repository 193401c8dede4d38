#pragma once
// LoopVerifier: decides whether two LoopKeyframe records see the same place, and if so measures
// their relative pose (docs/LOOP.md "Verification"):
//   1. ORB matching query -> candidate: brute-force Hamming, absolute threshold + Lowe ratio;
//   2. rigid 3D-3D RANSAC on the matched points (both have depth): solver/rigid_fit.h;
//   3. refinement of T_query_candidate with the pose-only optimiser (solver/pose_optimizer.h):
//      the candidate's 3D points against the query's [u, v, u_r] observations (RANSAC inliers),
//      plus the candidate's line-guidance samples against the query's 2D lines for LBD matches;
//      its covariance becomes the loop edge's information.
// Each stage has a threshold (min matches, min inliers, min inlier ratio, min refined inliers).
// Geometry cannot tell a true loop from repeated texture (identical modules ARE geometrically
// consistent); the plausibility of the implied correction is judged by the LoopCloser, which knows
// the odometry covariance between the two keyframes.
// Scratch allocated at construction; verify() allocates nothing. Deterministic.
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "pipeline/loop/loop_keyframe.h"
#include "pipeline/odometry/uncertainty_options.h"
#include "solver/camera_intrinsics.h"
#include "solver/noise_model.h"
#include "solver/pose_optimizer.h"
#include "solver/rigid_fit.h"
#include "solver/types.h"

namespace plumb::loop {

struct LoopVerifierOptions {
  int hamming_threshold = 50;       // ORB match acceptance (of 256 bits)
  float ratio = 0.8f;               // Lowe ratio: best < ratio * second best
  int line_hamming_threshold = 60;  // LBD
  float line_ratio = 0.8f;
  bool use_lines = true;  // line-guidance errors in the refinement
  // A line match (LBD descriptors alone: long parallel edges of windows, shelves and desks look
  // alike) enters the refinement only when the RANSAC pose of the points puts the candidate's
  // samples on the query's line: at least `line_gate_min_fraction` of them within
  // `line_gate_px` of it (sample pixels scaled by the octave), and overlapping the query
  // segment's own samples along it.
  double line_gate_px = 4.0;
  double line_gate_min_fraction = 0.6;
  // The N samples of one line are not N independent measurements of the pose (they share the 2D
  // fit and the 3D fit of one segment): each carries 1/N of a sample's information, so a line
  // weighs like one measurement in the refinement and in the loop edge's covariance.
  bool line_information_per_line = true;
  // A point whose two nearest candidate descriptors fail the ratio test enters RANSAC with both
  // (geometry decides) instead of being dropped. Repeated furniture makes the ratio test drop the
  // true matches of a revisit: office_loop with Kinect-like noise, 0.25 m from the first view,
  // kept 39 matches of its points (docs/LOOP.md "Recall"). Off by default: with the calibrated
  // loop covariance it let 4 wrong loops through on synth:loop seeds 1-2 (one beyond 5 cm / 2 deg)
  // and recalled no more revisits over the study (docs/LOOP.md "Study", the merged tree).
  bool ambiguous_pairs = false;
  int min_matches = 40;           // query points matched
  RigidRansacOptions ransac;
  int min_inliers = 35;           // RANSAC inliers
  double min_inlier_ratio = 0.3;  // RANSAC inliers / matches
  int min_refined_inliers = 35;   // point inliers after refinement
  // Reliability of the refinement (docs/LOOP.md "A loop that hinges on one feature"). A
  // feature's leverage (solver/pose_leverage.h) is the share of the pose's information, in its
  // best-determined direction, that the feature alone supplies; above 0.5 an error in it that the
  // inlier gate cannot see moves the pose by more than that gate in its own sigmas, so the
  // covariance no longer describes the pose. Such a feature (typically the one near point of a
  // view of a far wall: it alone fixes the translation) is taken out and the refinement solved
  // again without it, up to `max_unreliable_features` times; still unreliable after that, the
  // loop is `uncertain`. A feature is the inliers whose query pixels or candidate pixels lie
  // within `same_feature_px` of each other (one corner found at several ORB octaves, or two
  // keypoints sharing one depth reading: not independent measurements), or one matched line.
  double max_feature_leverage = 0.5;
  double same_feature_px = 3.0;
  int max_unreliable_features = 4;
  // The loop constraint's covariance (docs/LOOP.md "The loop constraint's covariance"). Both
  // ends of a loop are measurements: the candidate's 3D points and line samples come from its own
  // pixels and depth, as noisy as the query's. With `propagate_candidate_noise` each residual's
  // covariance is the query observation's PLUS the candidate point's back-projection covariance
  // (paper eqs. 26-28: pixel sigma by octave, depth sigma 0.0015 d^2) carried through the
  // projection, in the refinement's weights and so in its Hessian; off, the candidate is exact.
  bool propagate_candidate_noise = true;
  // Then calibrated like every published covariance (pipeline/odometry/uncertainty_options.h):
  // scaled by the refinement's a posteriori variance factor (its point residuals) when
  // `uncertainty.use_variance_factor`, and the rolling-shutter model error of EACH of the two
  // keyframe images added (zero for a global-shutter camera), as for a BA relative pose.
  bool calibrate_covariance = true;
  UncertaintyOptions uncertainty;        // the system's (the loop stage copies it in)
  double rolling_shutter_readout_s = 0;  // the camera's (the loop stage copies it in)
};

enum class LoopRejection : uint8_t {
  kNone = 0,
  kFewMatches,
  kFewInliers,
  kLowInlierRatio,
  kRefinement,   // refinement lost the inliers (or its covariance was degenerate)
  kImplausible,  // LoopCloser: the implied correction is beyond the odometry uncertainty
  kUncertain,    // LoopCloser: the measured relative pose is too uncertain to correct anything;
                 // or LoopVerifier: it still hinges on single features (max_feature_leverage)
  kRolledBack,   // LoopCloser: the corrected graph explains the covisible landmarks of both sides
                 // worse than before (loop_context_check.h): undone, never published
};
constexpr int kNumLoopRejections = 8;
const char* toString(LoopRejection r);

struct LoopMeasurement {
  LoopRejection rejection = LoopRejection::kFewMatches;
  // Pose of the query camera in the candidate camera (maps query-camera points into the candidate's).
  Eigen::Isometry3d T_candidate_query = Eigen::Isometry3d::Identity();
  // Covariance of the query pose with the candidate held fixed (left perturbation of
  // T_query_candidate, [rho; phi]): the pose graph's loop edge (candidate -> query) directly.
  Matrix6d covariance = Matrix6d::Identity();
  int matches = 0;
  int ransac_inliers = 0;
  int refined_inliers = 0;
  int line_matches = 0;  // LBD matches that passed the gate at the RANSAC pose
  int line_inliers = 0;   // their samples inlying after refinement
  int unreliable_features = 0;  // features taken out of the refinement for their leverage
  double max_leverage = 0;      // the largest feature leverage of the final refinement
  bool accepted() const { return rejection == LoopRejection::kNone; }
};

class LoopVerifier {
 public:
  LoopVerifier(const CameraIntrinsics& camera, const NoiseModelOptions& noise,
               const LoopVerifierOptions& options);
  ~LoopVerifier();
  LoopVerifier(const LoopVerifier&) = delete;
  LoopVerifier& operator=(const LoopVerifier&) = delete;

  // The candidate as the closer stores it (LoopCandidate: makeLoopCandidate of its record).
  LoopMeasurement verify(const LoopKeyframe& query, const LoopCandidate& candidate);
  const LoopVerifierOptions& options() const { return options_; }
  // The scratch allocated at construction (behind a pointer: not in sizeof(LoopVerifier)).
  static std::size_t scratchBytes();

 private:
  // The gate of a line match (options above), at the RANSAC pose.
  bool lineAgrees(const LoopLine& query_line, const Eigen::Vector3f* candidate_samples, std::size_t count,
                  const Eigen::Isometry3d& T_query_candidate) const;
  // Covariance of a candidate point (its pixel noise by octave, its depth noise) in the query
  // camera; zero when propagation is off or the depth is invalid.
  Eigen::Matrix3d candidateCovarianceInQuery(const Eigen::Vector3d& P_candidate, int octave,
                                             const Eigen::Isometry3d& T_query_candidate) const;
  // The feature (group of point inliers, or one line) with the largest leverage in `pose`; its
  // point group's representative (>= 0) or -(line + 1) in *feature.
  double weakestFeature(const PoseResult& pose, int num_points, int num_lines, const PoseOptimizerOptions& pose_options,
                        int* feature) const;
  // Drops the observations of `feature` from the refinement's arrays; called right after
  // weakestFeature(), whose stored roots it reads.
  void dropFeature(int feature, int* num_points, int* num_lines) const;
  // The refinement's covariance, calibrated (options above).
  Matrix6d calibratedCovariance(const PoseResult& pose, const PoseOptimizerOptions& pose_options) const;
  struct Scratch;
  CameraIntrinsics camera_;
  NoiseModelOptions noise_;
  LoopVerifierOptions options_;
  std::unique_ptr<Scratch> s_;
};

}  // namespace plumb::loop
