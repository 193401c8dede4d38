#pragma once
// Matching by projection with a predicted pose (ORB-SLAM style), for points and lines.
//
// Callers predict where their features (previous frame or map) fall in the current frame, in
// undistorted pixels, and pass them as candidates; the matcher searches the frame's features
// near each prediction and writes index pairs into caller-provided fixed-capacity buffers.
//
// Points: keypoints within `search_radius_px * scale^octave` of the prediction and within
// [octave-1, octave+1] of the predicted octave; best Hamming distance <= hamming_threshold, Lowe
// ratio best < ratio * second-best (when they are on different levels: ORB-SLAM's rule), each
// keypoint used once (the closer candidate wins), then an orientation-consistency histogram of
// (observed - predicted) angles keeps the three dominant bins.
// Lines: frame lines whose direction is within max_angle_deg of the predicted segment, whose
// endpoints distances to the predicted infinite line are small, which overlap the predicted
// segment along its direction, and whose LBD-style distance is below lbd_threshold with a ratio
// test; each frame line used once.
#include <array>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sensor/camera.h"
#include "pipeline/frontend/capacities.h"
#include "pipeline/frontend/frame_features.h"
#include "platform/fixed_vector.h"

namespace plumb {

struct PointMatcherOptions {
  float search_radius_px = 15;   // at octave 0; grows with scale^octave
  int hamming_threshold = 50;    // accept when best distance <= this (ORB-SLAM TH_HIGH = 100, LOW = 50)
  float ratio = 0.8f;            // best < ratio * second best
  bool check_orientation = true;
  int orientation_bins = 30;
  int octave_tolerance = 1;      // accept observed octave within +-this of the predicted one
};

struct LineMatcherOptions {
  int lbd_threshold = 80;             // max Hamming distance of the 256-bit line descriptors
  float ratio = 0.9f;                 // best < ratio * second best among geometric inliers
  float max_angle_deg = 10;           // direction difference (lines are undirected here)
  float max_endpoint_distance_px = 12;  // observed endpoints to the predicted infinite line
  float min_overlap = 0.3f;           // overlap / shorter length, measured along the predicted line
};

struct MatcherOptions {
  PointMatcherOptions points;
  LineMatcherOptions lines;
  float scale_factor = 1.2f;  // pyramid scale of the frame's keypoints (octave -> radius)
};

// A predicted point: where it should appear (undistorted px), what it looks like, at which
// octave; angle_deg < 0 means "unknown" (excluded from the orientation check).
struct PointCandidate {
  Eigen::Vector2f px_undist = Eigen::Vector2f::Zero();
  Descriptor256 descriptor;
  int8_t octave = 0;
  float angle_deg = -1;
};

// A predicted line segment (undistorted endpoints) and its descriptor.
struct LineCandidate {
  Eigen::Vector2f start_px = Eigen::Vector2f::Zero();
  Eigen::Vector2f end_px = Eigen::Vector2f::Zero();
  Descriptor256 descriptor;
};

struct PointMatch {
  uint16_t candidate = 0;  // index into the candidate array (or previous keypoint index)
  uint16_t keypoint = 0;   // index into FrameFeatures::keypoints
  uint16_t distance = 0;   // Hamming
};

struct LineMatch {
  uint16_t candidate = 0;
  uint16_t line = 0;  // index into FrameFeatures::lines
  uint16_t distance = 0;
};

using PointMatches = FixedVector<PointMatch, kMaxKeypoints>;
using LineMatches = FixedVector<LineMatch, kMaxLines>;

// Candidate buffers for frame-to-frame matching (projected previous features).
using PointCandidates = FixedVector<PointCandidate, kMaxKeypoints>;
using LineCandidates = FixedVector<LineCandidate, kMaxLines>;

class ProjectionMatcher {
 public:
  explicit ProjectionMatcher(const MatcherOptions& options = MatcherOptions());

  // Matches `count` candidates into `frame` (whose keypoint_grid must be built). `out` is
  // cleared first; returns the number of matches. Candidate indices must fit in uint16_t.
  int matchPoints(const PointCandidate* candidates, int count, const FrameFeatures& frame,
                  PointMatches& out);
  int matchLines(const LineCandidate* candidates, int count, const FrameFeatures& frame,
                 LineMatches& out) const;

  // Frame to frame: projects `previous` keypoints with depth (and lines with a 3D fit) through
  // T_current_previous into `current`, then matches as above. Match.candidate is the index of
  // the previous keypoint / line. Previous features without 3D are not matched.
  int matchPointsFrameToFrame(const PinholeCamera& camera, const FrameFeatures& previous,
                              const Eigen::Isometry3d& T_current_previous,
                              const FrameFeatures& current, PointMatches& out);
  int matchLinesFrameToFrame(const PinholeCamera& camera, const FrameFeatures& previous,
                             const Eigen::Isometry3d& T_current_previous,
                             const FrameFeatures& current, LineMatches& out);

  const MatcherOptions& options() const { return options_; }

 private:
  MatcherOptions options_;
  // scale_factor^octave for the octaves a pyramid has (std::pow once here, not per candidate).
  std::array<float, kPyramidLevels> octave_scale_{};
  float octaveScale(int octave) const {
    return octave >= 0 && octave < kPyramidLevels ? octave_scale_[octave]
                                                  : std::pow(options_.scale_factor, static_cast<float>(octave));
  }
  // Scratch (members so nothing is allocated per call).
  PointCandidates point_candidates_;
  LineCandidates line_candidates_;
  FixedVector<uint16_t, kMaxKeypoints> point_candidate_source_;
  FixedVector<uint16_t, kMaxLines> line_candidate_source_;
  std::array<int, kMaxKeypoints> best_candidate_for_keypoint_{};
  std::array<int, kMaxKeypoints> best_distance_for_keypoint_{};
  std::array<int8_t, kMaxKeypoints> grid_octave_{};  // matchPoints: keypoint octaves in grid order
};

}  // namespace plumb
