#pragma once
// Options of the odometry system, one struct per component, defaults documented on the members.
// tools/ fills them from the command line; nothing inside pipeline/ reads configuration itself.
#include <algorithm>

#include "solver/outlier_thresholds.h"
#include "pipeline/frontend/extractor_options.h"
#include "pipeline/odometry/matcher.h"
#include "pipeline/odometry/uncertainty_options.h"

namespace plumb {

struct TrackerOptions {
  // Use line-guidance features in pose optimisation (false = the points-only baseline).
  bool use_lines = true;
  // Frame-to-frame matching: fewer matches than this triggers a retry with a wider window, then
  // with zero motion (fast rotations break the constant-velocity guess).
  int min_frame_matches = 25;
  float wide_search_radius_px = 40;   // retry window at octave 0 (normal: the matcher's default)
  // Local-map tracking: search radius around the projection of local landmarks (octave 0).
  float local_map_search_radius_px = 4;
  // Tracking state from the final inlier count (points + lines with a majority of inlier samples):
  int min_inliers_ok = 40;    // >= this: ok
  int min_inliers_weak = 15;  // >= this: weak (pose kept, a keyframe is forced), below: lost
  // Pose optimisation: Gauss-Newton rounds, each followed by outlier classification (ORB-SLAM
  // runs 4 rounds of 10 iterations with chi-square thresholds at 95%).
  int pose_rounds = 4;
  int pose_iterations_per_round = 10;
  // A round ends when a Gauss-Newton step is shorter than this (|[rho; phi]|: metres and radians
  // together). 1e-5 (10 um, 10 urad) is far below the pose noise; the solver's own default of
  // 1e-6 took ~19 iterations a call on fr1/rpy where this takes ~15, since IRLS converges linearly.
  double pose_step_tolerance = 1e-5;
  OutlierChi2 chi2;  // outlier thresholds by error dof (solver/outlier_thresholds.h)
  // Landmarks farther than this (m) are not tracked (depth beyond it is too noisy to help).
  double max_landmark_distance_m = 8.0;
};

struct KeyframePolicyOptions {
  int max_frames_between = 30;       // ORB-SLAM: one second at 30 fps
  int min_frames_between = 0;        // 0 = whenever the criteria below fire
  float reference_ratio = 0.75f;     // inliers below this fraction of the reference KF's landmarks
  float reference_ratio_few_keyframes = 0.4f;  // while the map holds < 2 keyframes
  float close_depth_baselines = 40;  // "close" points: depth < this x baseline (ORB-SLAM: 40)
  int min_tracked_close = 100;       // need-close rule: tracked close < this ...
  int min_untracked_close = 70;      // ... and untracked close > this
  int min_inliers = 15;              // never insert a keyframe with fewer inliers than this
};

struct LocalMapperOptions {
  int ba_optimised_keyframes = 10;   // K: the new keyframe and its best covisible neighbours
  int ba_fixed_keyframes = 6;        // keyframes outside the window observing its landmarks
  int ba_iterations = 5;             // Levenberg-Marquardt iterations per keyframe
  // ... ending early after an accepted step that lowered the cost by less than this fraction.
  // On fr1/rpy the 4th and 5th steps gain < 1e-3 in most windows (measured: 38 and 47 of 60).
  double ba_function_tolerance = 1e-3;
  int max_ba_landmarks = 3000;       // points + line samples in one BA (extra ones are left out)
  OutlierChi2 chi2;  // outlier thresholds by error dof (solver/outlier_thresholds.h)
  // New landmarks per keyframe (closest first, ORB-SLAM's RGB-D rule), and the depth range.
  int max_new_points = 400;
  int max_new_lines = 80;
  double max_new_point_depth_m = 6.0;
  // Culling (ORB-SLAM): found/visible below this ratio, or fewer than `min_observers` keyframes
  // once `cull_after_keyframes` keyframes have passed since the landmark was made.
  float min_found_ratio = 0.25f;
  int min_observers = 2;
  int cull_after_keyframes = 3;
  float max_line_sample_outlier_ratio = 0.5f;  // lines whose BA samples fail this often go
  // Line samples keep their depth (docs/ODOMETRY.md "Line samples keep their depth"; `plumb run
  // --line-depth-anchor`): each sample enters local BA with a stereo observation in the keyframe
  // that back-projected it, its depth with a keypoint's sigma times `line_sample_depth_sigma_scale`
  // (2: line pixels sit on object edges, where depth is noisier, paper section V; 1 and 2 were
  // measured), its pixel only along its 2D line. Without it a sample seen by two keyframes has no
  // depth information at all: the first BAs of the noise-free office moved samples a median 35 mm
  // (p90 28 cm) across their lines, which tracking then used as fixed. OFF by default until its
  // interaction with loop closing is settled: the odometry gains on every line-rich family, but
  // head250's loops got worse (docs/ODOMETRY.md).
  bool anchor_line_sample_depth = false;
  double line_sample_depth_sigma_scale = 2.0;
  // Whether the observations local BA's solve() flags as outliers leave the map (and count toward
  // a line's sample outlier ratio above). Off: a binary-pair study (docs/ODOMETRY.md "Local BA
  // outlier culling") found no gain on average (head250 six-start mean --out -0.7 %,
  // --out-optimized +1.1 %) and a loss on the noise-free office scenes (+3-4 %), the proxy for
  // rendered datasets; the flags are still computed and counted (map.ba_outlier_flags).
  bool remove_ba_outliers = false;
  int covisible_keyframes_in_local_map = 10;   // keyframes whose landmarks make the snapshot
};

struct RelocalizerOptions {
  int hamming_threshold = 60;     // descriptor match acceptance
  float ratio = 0.8f;             // Lowe ratio (best < ratio x second best)
  int candidates = 5;             // keyframes verified geometrically, best match counts first
  int prefilter_features = 200;   // current-frame features used to rank stored keyframes
  int min_matches = 25;           // below: keyframe not tried
  int ransac_iterations = 200;
  double inlier_threshold_m = 0.05;  // 3D-3D residual of an inlier at 1 m (scaled by depth^2)
  int min_inliers = 30;
  uint64_t seed = 1;              // RANSAC sampling: fixed seed -> deterministic
  int max_lost_frames_before_new_map = 10;  // M: then a new map segment starts
};

struct OdometryOptions {
  ExtractorOptions extractor;
  MatcherOptions matcher;
  TrackerOptions tracker;
  KeyframePolicyOptions keyframes;
  LocalMapperOptions mapper;
  RelocalizerOptions relocalizer;
  UncertaintyOptions uncertainty;  // what the published covariances add (docs/UNCERTAINTY.md)
  // A map starts from a frame with this many keypoints with depth, or half of it plus lines.
  int min_initial_points = 100;
  int min_initial_lines = 10;
};

// N line-guidance samples per line (paper: 5), and whether lines are used at all. A 3D line fit
// needs min_line_inliers samples (default 3); with N = 2 both must be inliers, so it becomes N.
// N = 0 (or use_lines false) is the points-only system. N = 1 is left as given: validate() in
// pipeline/odometry/odometry_system.h refuses it (one sample fixes no 3D line).
inline void setLineSamples(int samples, bool use_lines, OdometryOptions* options) {
  options->extractor.line_samples = samples;
  if (samples >= 2) options->extractor.min_line_inliers = std::min(options->extractor.min_line_inliers, samples);
  options->tracker.use_lines = use_lines && samples > 0;
}

}  // namespace plumb
