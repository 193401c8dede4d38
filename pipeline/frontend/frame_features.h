#pragma once
// FrameFeatures: everything the front end measures in one frame, in fixed-capacity storage.
// This is the contract between extraction (pipeline/ front end) and tracking/mapping.
//
// Coordinates: `px` is where a feature was detected on the raw image; `px_undist` (and every line
// coefficient) is in the ideal pinhole image after undistortion, which is what matching by
// projection and the solver use. 3D quantities are in the camera frame of this image, metres.
#include <array>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "pipeline/frontend/capacities.h"
#include "pipeline/frontend/matcher_grid.h"
#include "platform/fixed_vector.h"

namespace plumb {

// std::array of Eigen fixed-size types filled with `value`. `std::array<Eigen::Vector3f, N> a{}`
// leaves the coefficients uninitialised (Eigen's default constructor does not zero), so a
// LineObservation{} would copy garbage (and GCC warns -Wmaybe-uninitialized in emplace_back).
template <typename T, std::size_t N>
std::array<T, N> filledArray(const T& value) {
  std::array<T, N> a;
  a.fill(value);
  return a;
}

// 256-bit binary descriptor: ORB's rotated BRIEF, or a 256-bit LBD code.
struct Descriptor256 {
  std::array<uint64_t, 4> words{};
};

// Bits that differ. x86-64 without -mpopcnt (the portable baseline) compiles
// __builtin_popcountll to a call into libgcc (~25 instructions a word, 7 M instructions a frame
// in matching and loop verification on head250), so there the count is SSE2 bit-slicing: bits
// summed in pairs, nibbles, bytes, then the bytes of each half by psadbw (~30 instructions for
// all 256 bits). aarch64 (NEON cnt) and -mpopcnt builds keep the builtin, which is inline there.
// tests/pipeline/frontend/frontend_kernels_test.cpp checks it against a bit-by-bit count.
inline int hammingDistance(const Descriptor256& a, const Descriptor256& b) {
#if defined(__SSE2__) && !defined(__POPCNT__)
  const __m128i* pa = reinterpret_cast<const __m128i*>(a.words.data());
  const __m128i* pb = reinterpret_cast<const __m128i*>(b.words.data());
  const __m128i m1 = _mm_set1_epi8(0x55), m2 = _mm_set1_epi8(0x33), m4 = _mm_set1_epi8(0x0f);
  auto byteCounts = [&](__m128i x) {
    x = _mm_sub_epi8(x, _mm_and_si128(_mm_srli_epi64(x, 1), m1));
    x = _mm_add_epi8(_mm_and_si128(x, m2), _mm_and_si128(_mm_srli_epi64(x, 2), m2));
    return _mm_and_si128(_mm_add_epi8(x, _mm_srli_epi64(x, 4)), m4);
  };
  const __m128i lo = byteCounts(_mm_xor_si128(_mm_loadu_si128(pa), _mm_loadu_si128(pb)));
  const __m128i hi = byteCounts(_mm_xor_si128(_mm_loadu_si128(pa + 1), _mm_loadu_si128(pb + 1)));
  // Each byte <= 8, so the two byte vectors add without overflow; psadbw sums 8 bytes per half.
  const __m128i sums = _mm_sad_epu8(_mm_add_epi8(lo, hi), _mm_setzero_si128());
  return _mm_cvtsi128_si32(sums) + _mm_cvtsi128_si32(_mm_unpackhi_epi64(sums, sums));
#else
  return __builtin_popcountll(a.words[0] ^ b.words[0]) + __builtin_popcountll(a.words[1] ^ b.words[1]) +
         __builtin_popcountll(a.words[2] ^ b.words[2]) + __builtin_popcountll(a.words[3] ^ b.words[3]);
#endif
}

struct KeypointObservation {
  Eigen::Vector2f px = Eigen::Vector2f::Zero();         // detected pixel (raw image)
  Eigen::Vector2f px_undist = Eigen::Vector2f::Zero();  // undistorted pixel
  float angle_deg = 0;      // ORB orientation
  float response = 0;       // FAST/Harris score
  int8_t octave = 0;        // pyramid level it was detected on
  float depth_m = 0;        // 0 = no valid depth: a 2D-only observation
  float u_right = -1;       // u_undist - fx*b/depth (paper V-D); < 0 when no depth
  Eigen::Vector3f P_cam = Eigen::Vector3f::Zero();       // back-projected point (depth_m > 0)
  // Information (inverse covariance) of the [u, v, u_r] observation from the paper's noise model
  // (pixel sigma from the octave, depth sigma quadratic in depth). Zero when depth_m == 0.
  Eigen::Matrix3f info_uvr = Eigen::Matrix3f::Zero();
};

struct LineObservation {
  Eigen::Vector2f start_px = Eigen::Vector2f::Zero();  // undistorted endpoints
  Eigen::Vector2f end_px = Eigen::Vector2f::Zero();
  // Normalised 2D line l = [a, b, c] / sqrt(a^2 + b^2) through the undistorted endpoints,
  // so l . [u, v, 1] is the signed pixel distance of (u, v) to the line (paper eq. 1).
  Eigen::Vector3d l = Eigen::Vector3d::Zero();
  float length_px = 0;
  float angle_rad = 0;      // direction of end - start in the image
  int8_t octave = 0;        // pyramid level the segment was detected on
  float response = 0;       // ranking score (e.g. length x gradient), best lines kept

  // Line-guidance samples (paper section V-D): evenly spaced on the segment, back-projected with
  // depth, outliers to the robust 3D line fit removed. Only the first num_samples are valid.
  uint8_t num_samples = 0;
  std::array<Eigen::Vector2f, kMaxLineSamples> sample_px =  // undistorted sample pixels
      filledArray<Eigen::Vector2f, kMaxLineSamples>(Eigen::Vector2f::Zero());
  std::array<Eigen::Vector3f, kMaxLineSamples> sample_P_cam =  // 3D samples, camera frame
      filledArray<Eigen::Vector3f, kMaxLineSamples>(Eigen::Vector3f::Zero());
  std::array<Eigen::Matrix3f, kMaxLineSamples> sample_cov =  // their 3D covariances
      filledArray<Eigen::Matrix3f, kMaxLineSamples>(Eigen::Matrix3f::Zero());
  // Robustly fitted 3D line (camera frame): a point on it and a unit direction; valid if has_3d.
  bool has_3d = false;
  Eigen::Vector3f line_point_cam = Eigen::Vector3f::Zero();
  Eigen::Vector3f line_dir_cam = Eigen::Vector3f::Zero();
};

struct FrameFeatures {
  FixedVector<KeypointObservation, kMaxKeypoints> keypoints;
  FixedVector<Descriptor256, kMaxKeypoints> keypoint_descriptors;  // parallel to keypoints
  FixedVector<LineObservation, kMaxLines> lines;
  FixedVector<Descriptor256, kMaxLines> line_descriptors;  // LBD, parallel to lines
  // Bucket grid over keypoints[i].px_undist, built by the extractor (matching by projection).
  KeypointGrid keypoint_grid;

  void clear() {
    keypoints.clear();
    keypoint_descriptors.clear();
    lines.clear();
    line_descriptors.clear();
    keypoint_grid.built = false;
  }
  // *this = other with only the used entries copied (the tracker keeps the last frame: the copy
  // assignment moves all ~290 kB of capacity, ~0.25 M instructions a frame). Every member above
  // must be copied here.
  void copyFrom(const FrameFeatures& other) {
    keypoints.assignUsed(other.keypoints);
    keypoint_descriptors.assignUsed(other.keypoint_descriptors);
    lines.assignUsed(other.lines);
    line_descriptors.assignUsed(other.line_descriptors);
    keypoint_grid = other.keypoint_grid;
  }
};

}  // namespace plumb
