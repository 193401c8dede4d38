#pragma once
// DepthSampler: attaches registered depth to the features of one frame.
//   keypoints: depth read at the raw (distorted) pixel `px` (depth is registered to the colour
//     image, which is distorted); valid -> depth_m, u_right = u - bf/d, P_cam from px_undist,
//     info_uvr from the paper's noise model (solver/noise_model.h); invalid, or on a depth
//     discontinuity (keypoint_edge_radius_px) -> 2D-only.
//   lines: N line-guidance samples evenly on the undistorted segment (ends excluded by a margin),
//     depth read at each sample's distorted pixel -- with the nearer surface preferred at depth
//     discontinuities and a widening search in holes -- back-projected with their 3D covariance,
//     then the robust 3D line fit (line_fit3d.h) drops off-line samples. A line keeps its samples
//     and has_3d only when at least min_line_inliers survive; otherwise it stays a 2D line.
#include <opencv2/core.hpp>

#include "sensor/camera.h"
#include "pipeline/frontend/extractor_options.h"
#include "pipeline/frontend/frame_features.h"
#include "solver/camera_intrinsics.h"

namespace plumb {

class DepthSampler {
 public:
  DepthSampler(const PinholeCamera& camera, const ExtractorOptions& options);

  // depth_raw: CV_16UC1 camera-sized (or empty: everything stays 2D-only).
  void attachDepth(const cv::Mat& depth_raw, double depth_factor, FrameFeatures& features) const;

  // Depth (m) at sub-pixel raw position (x, y). On a smooth surface (the 4 neighbours valid and
  // within the discontinuity threshold) the bilinear interpolation -- exact enough on slanted
  // planes, where rounding to a pixel costs centimetres at grazing angles. Otherwise the nearest
  // pixel's reading; with prefer_near_surface (line samples), the nearest surface in the edge
  // window when that pixel is a hole or sits on the far side of a discontinuity, then the nearest
  // reading within the hole radius. 0 when nothing valid.
  float depthAt(const cv::Mat& depth_raw, double depth_factor, float x, float y, bool prefer_near_surface) const;

 private:
  // True when the depth around `px` (raw pixel) spans two surfaces.
  bool onDepthEdge(const cv::Mat& depth_raw, double depth_factor, const Eigen::Vector2f& px) const;
  void sampleLine(const cv::Mat& depth_raw, double depth_factor, LineObservation& line) const;

  PinholeCamera camera_;
  ExtractorOptions options_;
  CameraIntrinsics intrinsics_;
};

}  // namespace plumb
