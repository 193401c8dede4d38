#pragma once
// OrbExtractor: ORB keypoints spread over the image, written into FrameFeatures.
//
// Per pyramid level: FAST-9 with 3x3 suppression; the level's share of
// num_features (geometric in the scale, as ORB-SLAM) is filled round-robin over grid cells
// (every cell's best corner first, then every cell's second best, ...), each round strongest
// first. FAST runs on the whole level at the high threshold, and again at the low threshold in
// the cells that found nothing, so weak-texture regions still get keypoints (ORB-SLAM's
// adaptive threshold). Then orientation by intensity centroid, the blur of just the pixels the
// chosen keypoints' tests read (their orientation bins known), rotated BRIEF on the blurred
// level, and undistortion of the keypoint coordinate.
#include <vector>

#include <opencv2/core.hpp>

#include "sensor/camera.h"
#include "pipeline/frontend/extractor_options.h"
#include "pipeline/frontend/frame_features.h"
#include "pipeline/frontend/image_pyramid.h"
#include "pipeline/frontend/orb_descriptor.h"
#include "pipeline/frontend/orb_fast.h"
#include "solver/zero_page_allocator.h"

namespace plumb {

class OrbExtractor {
 public:
  OrbExtractor(const PinholeCamera& camera, const ExtractorOptions& options);

  // grey: CV_8UC1 camera-sized (or greyInput() written in place). Builds the pyramid, appends
  // keypoints + descriptors to `out`.
  void extract(const cv::Mat& grey, FrameFeatures& out);
  // The pyramid's level 0: a caller that converts its colour image straight into it saves a copy.
  cv::Mat& greyInput() { return pyramid_.levelZero(); }

  const ImagePyramid& pyramid() const { return pyramid_; }
  double lastPyramidMs() const { return pyramid_ms_; }

 private:
  struct RankedCorner {
    FastCorner corner;
    int cell = 0;
    int rank = 0;  // position within its cell, strongest first
  };

  void selectOnLevel(int level, int wanted, FrameFeatures& out);
  // Blurs the parts of `level` the descriptors of its first `count` ranked corners read, given
  // their orientations (keypoints[i] is ranked corner i).
  void blurAroundKeypoints(int level, const KeypointObservation* keypoints, int count);
  static constexpr int kBlurBand = 8;      // rows blurred on the same runs of columns
  static constexpr int kMinBlurSpan = 16;  // px: one vector block of the blur
  static constexpr int kBlurSpanGap = 16;  // px: runs closer than this are blurred as one
  // Per orientation bin and phase (the keypoint's top sample row modulo kBlurBand), the columns
  // its tests read in each of the bands_per_keypoint_ bands it touches: bit dx + reach.
  void buildBandMasks();
  const uint64_t* bandMasks(int bin, int phase) const {
    return band_masks_.data() + (static_cast<size_t>(bin) * kBlurBand + phase) * bands_per_keypoint_;
  }

  PinholeCamera camera_;
  ExtractorOptions options_;
  ImagePyramid pyramid_;
  FastDetector fast_;
  OrbDescriber describer_;
  std::array<int, kPyramidLevels> features_per_level_{};
  // Sorting scratch, sized in the constructor, never grows: corners grouped by cell (ranked_),
  // then by rank (by_rank_, which first holds each raw corner's cell), and the counting-sort
  // bucket starts per cell and per rank. Sized for kMaxCornersPerLevel (40,000: 1.4 MB) but
  // from zero pages (all-zero bytes are the default values of these types, and every entry is
  // written before it is read): resident only up to the most corners a level has had.
  std::vector<RankedCorner, ZeroPageAllocator<RankedCorner>> ranked_, by_rank_;
  std::vector<int> cell_start_;
  std::vector<int, ZeroPageAllocator<int>> rank_start_;
  std::vector<char> cell_has_corner_;  // per spreading cell of the current level (sized for 8 px cells)
  // The columns blurAroundKeypoints blurs in each band of kBlurBand rows of the current level,
  // one bit each, blur_band_words_ words a band; and one band's runs of them.
  int blur_band_words_ = 0;
  std::vector<uint64_t> blur_band_bits_;
  std::vector<ImagePyramid::Span> blur_spans_;
  std::vector<uint64_t> band_masks_;  // see bandMasks()
  int bands_per_keypoint_ = 0;
  double pyramid_ms_ = 0;
};

}  // namespace plumb
