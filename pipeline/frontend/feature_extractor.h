#pragma once
// FeatureExtractor: one RGB-D frame in, FrameFeatures out (ORB keypoints + descriptors, LSD lines
// + LBD-style descriptors, depth back-projection with covariances, line-guidance samples with a
// robust 3D line fit, and the keypoint grid the projection matcher searches).
//
// Every working buffer (grey image, pyramid, blurred pyramid, FAST scores, candidate arrays) is
// allocated in the constructor for the camera's image size. In steady state extract() makes no
// heap allocation of its own; the only allocating calls are inside OpenCV's line segment detector
// (cv::LineSegmentDetector::detect builds internal lists) — documented in docs/FRONTEND.md and
// measured by tests/pipeline/frontend/allocation_test.cpp.
//
// Not thread-safe: one extractor per thread.
#include <memory>

#include "sensor/camera.h"
#include "pipeline/frontend/extractor_options.h"
#include "pipeline/frontend/frame_features.h"
#include "sensor/rgbd_image.h"

namespace plumb {

class OrbExtractor;
class LineExtractor;
class DepthSampler;

class FeatureExtractor {
 public:
  FeatureExtractor(const PinholeCamera& camera, const ExtractorOptions& options);
  ~FeatureExtractor();
  FeatureExtractor(const FeatureExtractor&) = delete;
  FeatureExtractor& operator=(const FeatureExtractor&) = delete;

  // Fills `out` (cleared first). `in.bgr` must be CV_8UC3 (or CV_8UC1) of the camera size;
  // `in.depth_raw` CV_16UC1 of the same size, or empty (then every feature is 2D-only).
  // Returns false (and leaves `out` empty) when the image does not match the camera.
  bool extract(const RgbdImage& in, FrameFeatures& out) { return extract(in.bgr, in.depth_raw, in.depth_factor, out); }
  // The same with the depth given apart from the colour (registered depth: depth_registration.h).
  bool extract(const cv::Mat& bgr, const cv::Mat& depth_raw, double depth_factor, FrameFeatures& out);

  const ExtractorTimings& lastTimings() const { return timings_; }
  const ExtractorOptions& options() const { return options_; }
  const PinholeCamera& camera() const { return camera_; }

 private:
  PinholeCamera camera_;
  ExtractorOptions options_;
  std::unique_ptr<OrbExtractor> orb_;
  std::unique_ptr<LineExtractor> lines_;
  std::unique_ptr<DepthSampler> depth_;
  float grid_u0_ = 0, grid_v0_ = 0, grid_u1_ = 0, grid_v1_ = 0;  // undistorted image bounds
  ExtractorTimings timings_;
};

}  // namespace plumb
