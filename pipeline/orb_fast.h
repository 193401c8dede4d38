#pragma once
// FAST-9 corner detection (16-pixel Bresenham circle of radius 3, an arc of 9 contiguous pixels
// all brighter or all darker than the centre by more than the threshold) with 3x3 non-maximum
// suppression. Written here (rather than cv::FAST) so it writes into fixed buffers and allocates
// nothing; the per-pixel rejection test is vectorised with OpenCV's universal intrinsics.
#include <cstdint>
#include <memory>

#include <opencv2/core.hpp>

namespace plumb {

struct FastCorner {
  int16_t x = 0, y = 0;  // level pixels
  uint8_t score = 0;     // largest threshold at which it is still a corner (>= detection threshold)
};

class FastDetector {
 public:
  // max_width/max_height: the largest image it will see (level 0); capacity: corners kept.
  FastDetector(int max_width, int max_height, int capacity);

  // Corners with score > threshold, at least `border` px from the image edge, that are 3x3
  // local maxima of the score (ties broken by raster order). Returns the count written to
  // corners(); `dropped()` counts corners lost to a full buffer (0 in practice).
  int detect(const cv::Mat& image, int threshold, int border);

  const FastCorner* corners() const { return kept_; }
  int dropped() const { return dropped_; }

 private:
  int capacity_;
  cv::Mat score_;       // CV_8UC1, max size, scores of raw corners (0 = not a corner)
  FastCorner* raw_;     // before suppression
  FastCorner* kept_;    // after suppression
  std::unique_ptr<FastCorner[]> storage_;
  int dropped_ = 0;
};

// Score of pixel `p` (pointer into an image with row stride `stride`): max over the 16 arcs of 9
// of the smallest brighter-or-darker difference; 0 when no arc is consistent.
int fastScore(const uint8_t* p, int stride);

}  // namespace plumb
