#pragma once
// ORB orientation (intensity centroid) and 256-bit rotated BRIEF.
//
// The test pattern is 256 point pairs drawn once, deterministically, from an isotropic Gaussian
// (sigma = patch/5, BRIEF's "G II" layout) and clipped to a disc of radius 13 px so that any
// rotation stays inside the 31x31 patch. Rather than rotating the pattern per keypoint, it is
// pre-rotated into 30 orientation bins of 12 degrees (as the ORB paper does) and stored as byte
// offsets; this relies on every pyramid level sharing one row stride (see ImagePyramid).
#include <array>
#include <cstdint>

#include <opencv2/core.hpp>

#include "pipeline/frontend/frame_features.h"

namespace plumb {

class OrbDescriber {
 public:
  static constexpr int kPatchRadius = 15;   // intensity-centroid disc radius (31x31 patch)
  static constexpr int kBorder = 16;        // keypoints must be this far from the level edge
  static constexpr int kAngleBins = 30;

  explicit OrbDescriber(int stride);

  // Orientation in degrees [0, 360) of the patch centred at `p` (level image, shared stride).
  float orientationDeg(const uint8_t* p) const;
  // Two implementations of both, the same integers (so the same angle and bits): the portable
  // one (OpenCV's universal intrinsics, SSE2 or NEON, and plain C++ for the tests) and, on x86-64
  // CPUs with SSSE3 (chosen at construction), byte multiply-adds (pmaddubsw) for the centroid
  // sums and add-with-carry bit packing for the tests. setKernelPath returns false, changing
  // nothing, for a path this CPU or build does not have (tests run both).
  enum class KernelPath { kPortable, kX86 };
  KernelPath kernelPath() const { return kernel_path_; }
  bool setKernelPath(KernelPath path);
  // Rotated BRIEF on the blurred level at `p`.
  void describe(const uint8_t* p_blurred, float angle_deg, Descriptor256& out) const;
  // The orientation bin describe() uses for `angle_deg`.
  static int angleBin(float angle_deg);
  // The farthest any test sample lies from the keypoint along x or y, over every orientation
  // bin (pixels, <= kMaxSampleReach): describe() reads the blurred level only within this square.
  int sampleReach() const { return sample_reach_; }
  static constexpr int kMaxSampleReach = 15;
  // The columns describe() reads on row dy (|dy| <= sampleReach()) of a keypoint in orientation
  // bin `bin`: bit dx + sampleReach() is set for every dx from the leftmost to the rightmost
  // sample on that row (gaps between samples included; 0 for a row without samples).
  uint64_t sampleRowMask(int bin, int dy) const { return sample_row_masks_[bin][dy + kMaxSampleReach]; }

 private:
  int stride_;
  int sample_reach_ = 0;
  std::array<int, kPatchRadius + 1> disc_half_width_{};  // half row width of the disc at dy
  // [bin][bit]: byte offsets of the first and the second sample of each test.
  std::array<std::array<int, 256>, kAngleBins> first_offsets_{}, second_offsets_{};
  std::array<std::array<uint64_t, 2 * kMaxSampleReach + 1>, kAngleBins> sample_row_masks_{};
  // Per |dy|, weights of the pixels p[-15 .. 16] of rows +-dy for the intensity centroid: dx (or
  // dy) inside the disc, 0 outside (16-bit multiply-adds, see orientationDeg).
  alignas(16) std::array<std::array<int16_t, 32>, kPatchRadius + 1> x_weight_{}, y_weight_{};
  // The same weights as signed bytes (|weight| <= 15) for the byte multiply-add path.
  alignas(16) std::array<std::array<int8_t, 32>, kPatchRadius + 1> x_weight_bytes_{}, y_weight_bytes_{};
  KernelPath kernel_path_ = KernelPath::kPortable;
};

}  // namespace plumb
