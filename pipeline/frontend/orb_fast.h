#pragma once
// FAST-9 corner detection (16-pixel Bresenham circle of radius 3, an arc of 9 contiguous pixels
// all brighter or all darker than the centre by more than the threshold) with 3x3 non-maximum
// suppression. Written here (rather than cv::FAST) so it writes into fixed buffers and allocates
// nothing; rejection tests and scores run on 16 pixels at a time with OpenCV's universal
// intrinsics (SSE2, the x86-64 baseline; NEON on ARM).
#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "solver/zero_page_allocator.h"

namespace plumb {

struct FastCorner {
  int16_t x = 0, y = 0;  // level pixels
  uint8_t score = 0;     // largest threshold at which it is still a corner (>= detection threshold)
};

class FastDetector {
 public:
  // max_width/max_height: the largest image it will see (level 0); capacity: corners kept.
  FastDetector(int max_width, int max_height, int capacity);

  // Detection in three steps so a caller can scan regions with different thresholds (ORB's
  // adaptive threshold): begin() clears the score map of `image`, scan() adds corners with
  // score > threshold inside [x0,x1)x[y0,y1) (clipped to `border` from the image edge; regions
  // must not overlap), suppress() keeps the 3x3 local maxima of the score (ties broken by raster
  // order) and returns their count, written to corners().
  void begin(const cv::Mat& image, int border);
  void scan(int threshold, int x0, int y0, int x1, int y1);
  int suppress();

  // Raw (unsuppressed) corners found so far, e.g. to see which regions are still empty.
  int numRaw() const { return num_raw_; }
  const FastCorner* rawCorners() const { return raw_; }
  const FastCorner* corners() const { return kept_; }
  int dropped() const { return dropped_; }

 private:
  int capacity_;
  cv::Mat score_;       // CV_8UC1, max size, scores of raw corners (0 = not a corner)
  FastCorner* raw_;     // before suppression
  FastCorner* kept_;    // after suppression
  // 2 x capacity corners (raw, kept) from zero pages: all-zero bytes are default FastCorners, and
  // only as many as a level has had become resident.
  std::vector<FastCorner, ZeroPageAllocator<FastCorner>> storage_;
  int dropped_ = 0;
  int num_raw_ = 0;
  cv::Mat image_;  // header of the image being scanned (no copy)
  int border_ = 3;
};

// Score of pixel `p` (pointer into an image with row stride `stride`): max over the 16 arcs of 9
// of the smallest brighter-or-darker difference; 0 when no arc is consistent.
int fastScore(const uint8_t* p, int stride);

}  // namespace plumb
