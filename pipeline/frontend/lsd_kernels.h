#pragma once
// Small kernels of LineSegmentDetector's region growing, here so that tests can hold every
// implementation against the portable one (tests/pipeline/frontend/lsd_kernels_test.cpp).
//
// Pixel states are bytes: kLsdFree (above the gradient threshold, in no region yet) or kLsdUsed.
// The neighbour mask of pixel p in an image `w` pixels wide is a 12-bit word with the free states
// of the 3x3 neighbourhood in raster order, one row per nibble:
//   bits 0..2  : p - w - 1, p - w, p - w + 1
//   bits 4..6  : p - 1,     p,     p + 1
//   bits 8..10 : p + w - 1, p + w, p + w + 1
// (bits 3, 7, 11 are 0). Each row is read as one 4-byte word, so the state array must be readable
// from p - w - 1 to p + w + 2.
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace plumb {

// Free = 1 so that a state byte is directly a bit.
constexpr uint8_t kLsdFree = 1, kLsdUsed = 0;

// Portable: the three state bytes of a row (1 or 0) moved to bits 0..2 by one multiply: byte k
// (bit 8k) times 2^(14 - 7k) lands on bit 14 + k, and no two partial products share a bit.
inline uint32_t lsdNeighbourMaskPortable(const uint8_t* state, int p, int w) {
  auto row = [&](int i) {
    uint32_t v;
    std::memcpy(&v, state + i - 1, 4);
    return (((v & 0x010101u) * 0x4081u) >> 14) & 7u;
  };
  return row(p - w) | row(p) << 4 | row(p + w) << 8;
}

#if defined(__SSE2__)
// SSE2 (the x86-64 baseline): the three 4-byte rows in one register, each state shifted to its
// byte's sign bit, one movemask.
inline uint32_t lsdNeighbourMaskSse2(const uint8_t* state, int p, int w) {
  auto row = [&](int i) {
    int v;
    std::memcpy(&v, state + i - 1, 4);
    return _mm_cvtsi32_si128(v);
  };
  const __m128i rows = _mm_unpacklo_epi64(_mm_unpacklo_epi32(row(p - w), row(p)), row(p + w));
  return static_cast<uint32_t>(_mm_movemask_epi8(_mm_slli_epi16(rows, 7))) & 0x777u;
}
#endif

inline uint32_t lsdNeighbourMask(const uint8_t* state, int p, int w) {
#if defined(__SSE2__)
  return lsdNeighbourMaskSse2(state, p, w);
#else
  return lsdNeighbourMaskPortable(state, p, w);
#endif
}

}  // namespace plumb
