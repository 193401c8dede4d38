#pragma once
// ExtractorOptions: every tunable of the measurement front end (ORB points, LSD lines + LBD-style
// descriptors, depth back-projection with the paper's noise model, line-guidance sampling).
// Defaults are the values used by `plumb bench frontend` and the tests; tools/ may override them.
#include <string>

#include "pipeline/frontend/capacities.h"
#include "solver/noise_model.h"

namespace plumb {

struct ExtractorOptions {
  // ---- ORB keypoints -------------------------------------------------------------------------
  int num_features = 1000;        // target per frame (spread over levels geometrically, ORB-SLAM style)
  int num_levels = 8;             // pyramid levels (<= kPyramidLevels)
  float scale_factor = 1.2f;      // between consecutive levels
  int fast_threshold_high = 20;   // FAST threshold preferred in each cell ...
  int fast_threshold_low = 7;     // ... and the fallback so weak-texture cells still get corners
  int cell_size_px = 32;          // spreading grid cell (in each level's own pixels)

  // ---- Line segments -------------------------------------------------------------------------
  int max_lines = 150;            // keep the best K by response (length x mean gradient); <= kMaxLines
  float min_line_length_px = 25;  // minimum length in full-resolution pixels
  // Pyramid level LSD runs on (0 = full resolution). Level 4 (scale 1.2^4 = 2.07) is ~half
  // resolution: 4x fewer pixels, endpoints are scaled back up to level-0 pixels.
  int line_level = 4;
  // Detector: our lean LSD-style detector (line_segment_detector.h, ~1 ms at level 4, allocation
  // free) or OpenCV imgproc's LineSegmentDetector (~6.4 ms at level 4, allocates per call).
  bool use_opencv_lsd = false;

  // ---- Depth ---------------------------------------------------------------------------------
  float min_depth_m = 0.2f;       // readings outside [min, max] are treated as holes
  float max_depth_m = 8.0f;
  // A keypoint whose depth window (radius in px) spans a depth discontinuity stays 2D-only:
  // corners on silhouettes are usually T-junctions of two surfaces, so no single depth (and no
  // fixed 3D point) belongs to them. 0 disables the check.
  int keypoint_edge_radius_px = 2;

  // ---- Line-guidance samples (paper V-D) -------------------------------------------------------
  int line_samples = 5;           // N points per line; 0 = points only; <= kMaxLineSamples
  float sample_end_margin = 0.05f;     // samples span [margin, 1 - margin] of the segment
  int depth_edge_radius_px = 1;   // take the nearest surface within this window (lines sit on edges)
  int depth_hole_radius_px = 3;   // if that window has no reading, widen the search up to this
  // Robust 3D line fit: a sample is an inlier when its distance to the line is below
  // max(fit_min_threshold_m, fit_sigma_multiplier * sigma_d(depth)).
  float fit_sigma_multiplier = 3.0f;
  float fit_min_threshold_m = 0.01f;
  int min_line_inliers = 3;       // has_3d needs at least this many surviving samples

  // ---- Noise model (paper V-D, solver/noise_model.h): sigma_p = 1 px * 1.2^octave,
  // sigma_d = 0.0015 * d^2 m. Its scale_factor should equal `scale_factor` above.
  NoiseModelOptions noise;
};

// Empty when usable; otherwise which option is out of range (tools/ turn this into a Status).
// FeatureExtractor clamps out-of-range values, so callers that skip this still do not crash.
inline std::string validate(const ExtractorOptions& o) {
  if (o.num_features < 1 || o.num_features > static_cast<int>(kMaxKeypoints))
    return "num_features must be in 1.." + std::to_string(kMaxKeypoints);
  if (o.num_levels < 1 || o.num_levels > kPyramidLevels) return "num_levels must be in 1.." + std::to_string(kPyramidLevels);
  if (!(o.scale_factor > 1.0f)) return "scale_factor must be > 1";
  if (o.fast_threshold_low < 1 || o.fast_threshold_high < o.fast_threshold_low || o.fast_threshold_high > 254)
    return "FAST thresholds must satisfy 1 <= low <= high <= 254";
  if (o.cell_size_px < 8) return "cell_size_px must be >= 8";
  if (o.max_lines < 0 || o.max_lines > static_cast<int>(kMaxLines)) return "max_lines must be in 0.." + std::to_string(kMaxLines);
  if (o.line_level < 0 || o.line_level >= o.num_levels) return "line_level must be a pyramid level";
  if (o.line_samples < 0 || o.line_samples > static_cast<int>(kMaxLineSamples))
    return "line_samples must be in 0.." + std::to_string(kMaxLineSamples);
  if (!(o.min_depth_m > 0) || !(o.max_depth_m > o.min_depth_m)) return "need 0 < min_depth_m < max_depth_m";
  if (o.min_line_inliers < 2) return "min_line_inliers must be >= 2";
  return "";
}

// Cost of the last extract() call in milliseconds: wall clock (steady clock) and, in the *_cpu_ms
// fields, this thread's CPU time (CLOCK_THREAD_CPUTIME_ID), which does not count time the thread
// waited for a core -- the honest number on a loaded machine.
struct ExtractorTimings {
  double pyramid_ms = 0;   // grey conversion + pyramid (the descriptor blur is in orb_ms, per level)
  double orb_ms = 0;       // FAST, spreading, orientation, rBRIEF (includes pyramid_ms)
  double lines_ms = 0;     // LSD + ranking + LBD-style descriptors
  double depth_ms = 0;     // keypoint depth/noise + line samples + robust 3D fits
  double total_ms = 0;
  double orb_cpu_ms = 0, lines_cpu_ms = 0, depth_cpu_ms = 0, total_cpu_ms = 0;
  int num_keypoints = 0;
  int num_keypoints_with_depth = 0;
  int num_lines = 0;
  int num_lines_3d = 0;
  int lsd_raw_segments = 0;  // before the length filter / top-K
};

}  // namespace plumb
