#pragma once
// LineSegmentDetector: a lean line segment detector in the spirit of LSD (von Gioi et al. 2012),
// written here because OpenCV's LSD costs ~6.4 ms even on a half-resolution 309x231 image on
// this machine (double-precision angles, per-call allocations), most of the 10 ms front-end budget.
//
// Same first stages as LSD: a 2x2 gradient; pixels above the gradient threshold rho = q/sin(tau)
// (q = 2 grey levels of quantisation noise, tau = 22.5 deg) visited in descending gradient
// magnitude (a 1024-bin bucket sort); 8-connected region growing of pixels whose gradient
// direction is within tau of the region's running mean direction; the region's rectangle from the
// magnitude-weighted centroid and principal axis. LSD's a-contrario validation (NFA) and
// rectangle refinement are replaced by cheap tests: a minimum length, a maximum RMS distance of
// the region's pixels across its axis and a maximum mean thickness (pixels per unit length),
// which reject curved, blob-like and noisy regions. (LSD's rectangle-density test is too strict
// for the slightly curved edges of a distorted, blurred Kinect image without its refinement.) Angles are never computed: directions are unit vectors and alignment is a dot
// product against cos(tau).
//
// Segment direction convention: the gradient (dark -> bright) points to the LEFT of start -> end
// (in image coordinates, y down), so the same edge is reported in the same direction from frame to
// frame (the line descriptor relies on that). All buffers are allocated in the constructor.
#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "solver/zero_page_allocator.h"

namespace plumb {

struct LineSegmentDetectorOptions {
  float quantization = 2.0f;        // q: grey-level quantisation error
  float angle_tolerance_deg = 22.5f;  // tau
  float max_rms_width_px = 1.25f;   // weighted RMS distance of region pixels across the axis
  float max_thickness_px = 4.5f;    // region pixels per pixel of length
};

struct DetectedSegment {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // image pixels (pixel centres at integers)
  float length = 0;
  float mean_gradient = 0;               // mean gradient magnitude of the region
};

class LineSegmentDetector {
 public:
  LineSegmentDetector(int max_width, int max_height, const LineSegmentDetectorOptions& options = {});

  // Detects segments at least `min_length` long in `image` (CV_8UC1, at most the constructor
  // size) into out[0..capacity); returns the number written.
  int detect(const cv::Mat& image, float min_length, DetectedSegment* out, int capacity);

 private:
  bool regionToSegment(int region_size, float min_length, DetectedSegment* segment) const;
  void regionBox(int region_size, int* x_min, int* x_max, int* y_min, int* y_max) const;

  LineSegmentDetectorOptions options_;
  int max_width_, max_height_;
  int width_ = 0, height_ = 0;
  std::vector<float> magnitude_, dir_x_, dir_y_;  // per pixel; unit gradient direction
  std::vector<uint8_t> state_;                    // 1 free, 0 used or below threshold (padded, see .cpp)
  // Sized for every pixel but filled only up to the candidates / the largest region: zero pages
  // (the same zeros resize() would write), resident only as far as a frame reaches.
  template <class T>
  using Scratch = std::vector<T, ZeroPageAllocator<T>>;
  std::vector<int> bucket_start_;
  Scratch<int> ordered_;                          // bucket sort of candidate pixels
  Scratch<int> candidate_;                        // candidates in raster order ...
  Scratch<uint16_t> candidate_bin_;               // ... and their magnitude bins
  Scratch<int> region_;                           // pixel indices of the growing region
  struct RegionPixel {
    int16_t x, y;
  };
  Scratch<RegionPixel> region_xy_;                // ... and their coordinates (no divisions)
};

}  // namespace plumb
