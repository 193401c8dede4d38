#pragma once
// LineExtractor: line segments on one pyramid level -- our LSD-style detector
// (line_segment_detector.h) or, with use_opencv_lsd, OpenCV imgproc's LineSegmentDetector (no
// refinement, no internal rescale: the pyramid already did that) -- scaled back to level-0 pixels,
// filtered by minimum length, the best max_lines kept (longest first: length is what makes a
// segment both repeatable and well-constrained), endpoints undistorted, normalised 2D line
// coefficients computed, and an LBD-style descriptor attached.
//
// Allocation: none with our detector. cv::LineSegmentDetector::detect allocates its internal
// images and region lists on every call (documented in docs/FRONTEND.md); the output vector keeps
// its reserved capacity.
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sensor/camera.h"
#include "pipeline/frontend/extractor_options.h"
#include "pipeline/frontend/frame_features.h"
#include "pipeline/frontend/image_pyramid.h"
#include "pipeline/frontend/line_descriptor.h"
#include "pipeline/frontend/line_segment_detector.h"

namespace plumb {

class LineExtractor {
 public:
  LineExtractor(const PinholeCamera& camera, const ExtractorOptions& options);

  // Appends up to options.max_lines lines + descriptors to `out`.
  void extract(const ImagePyramid& pyramid, FrameFeatures& out);
  int lastRawSegments() const { return last_raw_segments_; }

 private:
  PinholeCamera camera_;
  ExtractorOptions options_;
  LineDescriptorOptions descriptor_options_;
  cv::Ptr<cv::LineSegmentDetector> lsd_;  // only with use_opencv_lsd
  LineSegmentDetector detector_;
  std::vector<DetectedSegment> detected_;  // sized once
  std::vector<cv::Vec4f> segments_;  // reserved once
  std::vector<std::pair<float, int>> ranked_;  // (length, index), reserved once
  int last_raw_segments_ = 0;
};

// Fills the 2D geometry of `line` from undistorted endpoints (l normalised, length, angle).
void setLineGeometry(const Eigen::Vector2f& start_px, const Eigen::Vector2f& end_px, LineObservation& line);

}  // namespace plumb
