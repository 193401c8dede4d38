#pragma once
// ImagePyramid: the grey image at num_levels scales (level i is 1/scale^i of level 0) plus a
// Gaussian-blurred copy of every level for the binary descriptors.
//
// Allocation: build() allocates nothing. The blur is our own separable filter (cv::GaussianBlur
// builds a filter engine, ~10 heap allocations per call) and so is the bilinear downsampler
// (cv::resize allocates 2-3 small buffers per call); its sampling tables are built once here.
//
// All levels live as ROIs of ONE buffer whose row stride is level 0's width, so a pixel offset
// (dy * stride + dx) means the same thing on every level: the rotated-BRIEF and FAST offset
// tables are computed once. Buffers are allocated in the constructor; build() only writes.
#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/frontend/capacities.h"

namespace plumb {

class ImagePyramid {
 public:
  ImagePyramid(int width, int height, int num_levels, float scale_factor);

  // grey: CV_8UC1 of the level-0 size. Fills every level and the blurred levels. `grey` may be
  // levelZero() itself (written by the caller in place: no copy).
  void build(const cv::Mat& grey);
  // Fills the levels only; blurRect() or blurRowSpans() then blurs just the parts a caller reads
  // (ORB blurs the columns its keypoints' tests read). A blurred pixel has the same value either
  // way; pixels never blurred keep older contents.
  void buildLevels(const cv::Mat& grey);
  // Blurs [x0, x1) x [y0, y1) of `level` (clipped to the level) into blurred(level).
  void blurRect(int level, int x0, int y0, int x1, int y1);
  // Blurs the columns [x0, x1) of each span on rows [y0, y1) of `level` (clipped to the level)
  // into blurred(level). The spans must lie inside the level and be non-empty; they may overlap
  // (the same values are written twice). One call shares each row's set-up among its spans.
  struct Span {
    int x0, x1;
  };
  void blurRowSpans(int level, int y0, int y1, const Span* spans, int num_spans);

  int numLevels() const { return num_levels_; }
  float scale(int level) const { return scales_[level]; }  // scale_factor^level
  const cv::Mat& level(int i) const { return levels_[i]; }
  // Level 0 for a caller to write the next grey image into (e.g. by cv::cvtColor, which keeps
  // the buffer as its size and type match) before build(levelZero()).
  cv::Mat& levelZero() { return levels_[0]; }
  const cv::Mat& blurred(int i) const { return blurred_levels_[i]; }
  int stride() const { return static_cast<int>(buffer_.step[0]); }  // bytes per row, every level
  // Whether downsample() can gather level i's bilinear pairs by byte shuffles (tests).
  bool shuffleGatherPossible(int level) const { return shuffle_ok_[level]; }
  // The blur's two implementations, the same integers: byte multiply-adds (SSSE3 pmaddubsw,
  // x86-64 CPUs that have it, chosen at construction) or the portable 16-bit form (OpenCV's
  // universal intrinsics: SSE2, NEON). setBlurPath returns false, changing nothing, for a path
  // this CPU or build does not have (tests run both).
  enum class BlurPath { kPortable, kByteMultiplyAdd };
  BlurPath blurPath() const { return blur_path_; }
  bool setBlurPath(BlurPath path);

 private:
  int num_levels_;
  std::array<float, kPyramidLevels> scales_{};
  // The separable 7-tap blur of src on the spans of rows [y0, y1) into dst (spans inside the
  // image, non-empty), borders reflected at the image edges (not at a span's): every pixel gets
  // the value a whole-image pass gives.
  void blur(const cv::Mat& src, cv::Mat& dst, int y0, int y1, const Span* spans, int num_spans);
  void downsample(int level);  // levels_[level - 1] -> levels_[level], bilinear

  // Bilinear sampling table of one axis of one level: source index and the 11-bit fixed-point
  // weight of index + 1 (weight of index is 2048 - that). Same half-pixel-centre convention as
  // cv::resize INTER_LINEAR, so the pyramid is close to what OpenCV would give.
  struct Tap {
    int index0, index1;  // index1 = index0 + 1, clamped to the last pixel
    int weight;          // of index1, in 1/2048
  };
  static constexpr int kWeightBits = 11;
  static void appendTaps(int src_size, int dst_size, std::vector<Tap>& taps);
  std::vector<Tap> x_taps_, y_taps_;                          // all levels, concatenated
  std::array<int, kPyramidLevels> x_tap_start_{}, y_tap_start_{};  // each level's first entry
  std::vector<int32_t> x_weight_pairs_;  // per x tap: (2048 - weight) | weight << 16, two int16 lanes
  cv::Mat high_row_, low_row_;      // CV_16SC1, one source row + padding: the vertical pass, split
  // Byte-shuffle form of the horizontal pass (x86-64 with SSSE3, aarch64): the four (x0, x0 + 1)
  // pairs of 4 consecutive outputs lie within 8 source elements (scale 1.2: ~5.8), so one 16-byte
  // load at the group's first index0 and one byte shuffle replace 4 scalar loads. Per group of 4
  // outputs of the vector loop: that index and the shuffle's 16 byte indices. shuffle_ok_ is
  // false for a level whose taps spread further (larger scale factors): the scalar-gather path.
  std::vector<int32_t> group_base_;
  std::vector<uint8_t> group_shuffle_;
  std::array<int, kPyramidLevels> group_start_{};
  std::array<bool, kPyramidLevels> shuffle_ok_{};

  cv::Mat buffer_, blurred_buffer_;
  cv::Mat row_filtered_;            // CV_16UC1, one row + 3 px padding each side: the blur's vertical pass
  cv::Mat row_filtered_bytes_;      // CV_8UC1, the same for the byte path (the vertical result fits a byte)
  BlurPath blur_path_ = BlurPath::kPortable;
  std::array<int, 7> kernel_{};     // 7-tap Gaussian, sigma 2, fixed point (sum 256)
  std::array<cv::Mat, kPyramidLevels> levels_, blurred_levels_;
};

}  // namespace plumb
