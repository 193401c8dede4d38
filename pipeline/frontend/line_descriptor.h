#pragma once
// A compact LBD-style line descriptor (after Zhang & Koch 2013, "An efficient and robust line
// segment matching approach based on LBD descriptor and pairwise geometric consistency"),
// computed here because OpenCV's BinaryDescriptor costs ~45 us per line on this machine.
//
// The support region is m = 9 bands of w rows parallel to the segment. At K positions along the
// segment and every row, the image gradient is split into its components across (g_n) and along
// (g_d) the line; each band accumulates the four LBD sums (g_n > 0, -(g_n < 0), g_d > 0,
// -(g_d < 0)) separately for the first and second half of the segment: 8 numbers per band.
// Rows are weighted by a Gaussian across the region (LBD's global weighting), so the bands near
// the line dominate. The 72 numbers are binarised into 256 bits by fixed comparisons:
//   208 bits: each of the 8 numbers compared between every pair of bands at most 4 apart
//    48 bits: within-band comparisons (positive vs negative sums, first vs second half)
// The segment direction (from LSD's gradient convention) fixes which side is "left", so the code
// is rotation invariant; it is not invariant to the segment being reported reversed.
#include <opencv2/core.hpp>

#include "pipeline/frontend/frame_features.h"

namespace plumb {

struct LineDescriptorOptions {
  int num_bands = 9;    // fixed by the bit layout above
  int band_width = 3;   // rows per band, in pixels of the image the descriptor is computed on
  int max_positions = 32;  // samples along the segment (fewer for short segments)
};

// image: CV_8UC1 (the pyramid level the segment was detected on); start/end in its pixels.
void computeLineDescriptor(const cv::Mat& image, const cv::Point2f& start, const cv::Point2f& end,
                           const LineDescriptorOptions& options, Descriptor256& out);

}  // namespace plumb
