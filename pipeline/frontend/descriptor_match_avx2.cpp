// The AVX2 build of descriptor_match.h's scans (x86-64, chosen at run time by descriptor_match.cpp):
// the distances of four descriptors at a time, each descriptor's 256 bits in one register (nibble
// counts by pshufb, bytes summed by psadbw, the four sums gathered into one vector), against the
// scan's current limit in one comparison. A block of four with a distance below the limit goes
// through the scalar updates in index order, with the limit as it is at each one, exactly as the
// one-at-a-time scan (which skips only what cannot change a result): the same results. The
// both-ways scan updates four columns' bests at once (min and blend).
#include "pipeline/frontend/descriptor_match_avx2.h"

#if PLUMB_SCAN_AVX2
#include <immintrin.h>

namespace plumb::descriptor_scan_avx2 {
namespace {

#define PLUMB_AVX2_TARGET __attribute__((target("avx2,popcnt")))

// Bit counts of the four 64-bit words of q ^ o, one per 64-bit lane.
PLUMB_AVX2_TARGET inline __m256i wordCounts(__m256i q, const Descriptor256& o) {
  const __m256i nibble_bits = _mm256_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4, 0, 1, 1, 2, 1, 2, 2, 3,
                                               1, 2, 2, 3, 2, 3, 3, 4);
  const __m256i low4 = _mm256_set1_epi8(0x0f);
  const __m256i x = _mm256_xor_si256(q, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(o.words.data())));
  const __m256i lo = _mm256_shuffle_epi8(nibble_bits, _mm256_and_si256(x, low4));
  const __m256i hi = _mm256_shuffle_epi8(nibble_bits, _mm256_and_si256(_mm256_srli_epi16(x, 4), low4));
  return _mm256_sad_epu8(_mm256_add_epi8(lo, hi), _mm256_setzero_si256());
}

// The distances of o[0..3] to q, as four 32-bit lanes in index order.
PLUMB_AVX2_TARGET inline __m128i fourDistances(__m256i q, const Descriptor256* o) {
  // Each word count is <= 64: two candidates share a 64-bit lane (low and high 32 bits).
  const __m256i c01 = _mm256_or_si256(wordCounts(q, o[0]), _mm256_slli_epi64(wordCounts(q, o[1]), 32));
  const __m256i c23 = _mm256_or_si256(wordCounts(q, o[2]), _mm256_slli_epi64(wordCounts(q, o[3]), 32));
  // Per 128-bit half: [w0 of 0, 1, 2, 3] + [w1 of 0, 1, 2, 3] (words 2 and 3 in the upper half).
  const __m256i s = _mm256_add_epi32(_mm256_unpacklo_epi64(c01, c23), _mm256_unpackhi_epi64(c01, c23));
  return _mm_add_epi32(_mm256_castsi256_si128(s), _mm256_extracti128_si256(s, 1));
}

PLUMB_AVX2_TARGET inline int distance(const Descriptor256& a, const Descriptor256& b) {
  return __builtin_popcountll(a.words[0] ^ b.words[0]) + __builtin_popcountll(a.words[1] ^ b.words[1]) +
         __builtin_popcountll(a.words[2] ^ b.words[2]) + __builtin_popcountll(a.words[3] ^ b.words[3]);
}

// nearestTwoBelow's update for one distance (strict: the first wins ties).
inline void update(NearestTwo& r, int dist, int index) {
  if (dist >= r.second) return;
  if (dist < r.best) {
    r.second = r.best;
    r.second_index = r.best_index;
    r.best = dist;
    r.best_index = index;
  } else {
    r.second = dist;
    r.second_index = index;
  }
}

}  // namespace

PLUMB_AVX2_TARGET NearestTwo nearestTwoBelow(const Descriptor256& d, const Descriptor256* others, std::size_t n,
                                             int bound) {
  NearestTwo r;
  r.best = r.second = bound;
  const __m256i q = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(d.words.data()));
  __m128i limit = _mm_set1_epi32(bound);
  const Descriptor256* const blocks_end = others + (n & ~std::size_t(3));
  for (const Descriptor256* p = others; p != blocks_end; p += 4) {
    const __m128i dist = fourDistances(q, p);
    if (_mm_movemask_epi8(_mm_cmpgt_epi32(limit, dist)) == 0) continue;  // all >= second
    alignas(16) int four[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(four), dist);
    const int j = int(p - others);
    for (int i = 0; i < 4; ++i) update(r, four[i], j + i);
    limit = _mm_set1_epi32(r.second);
  }
  for (std::size_t j = n & ~std::size_t(3); j < n; ++j) update(r, distance(d, others[j]), int(j));
  return r;
}

PLUMB_AVX2_TARGET void nearestBothWays(const Descriptor256* a, std::size_t na, const Descriptor256* b, std::size_t nb,
                                       int row_bound, int col_bound, NearestTwo* rows, int* col_best, int* col_index) {
  for (std::size_t l = 0; l < nb; ++l) {
    col_best[l] = col_bound;
    col_index[l] = -1;
  }
  const Descriptor256* const blocks_end = b + (nb & ~std::size_t(3));
  for (std::size_t k = 0; k < na; ++k) {
    NearestTwo r;
    r.best = r.second = row_bound;
    const __m256i q = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a[k].words.data()));
    const __m128i row_index = _mm_set1_epi32(int(k));
    __m128i second4 = _mm_set1_epi32(r.second);
    // Four columns a step: a column's update (strictly below its best, this row's index) does not
    // depend on the row's state, so the four are updated at once; the row's updates go through
    // the scalar rule in index order, only where a distance is below its second best.
    for (const Descriptor256* p = b; p != blocks_end; p += 4) {
      const __m128i dist = fourDistances(q, p);
      const std::size_t l = std::size_t(p - b);
      __m128i* const best4 = reinterpret_cast<__m128i*>(col_best + l);
      const __m128i cols = _mm_loadu_si128(best4);
      const __m128i col_lower = _mm_cmpgt_epi32(cols, dist);
      const __m128i row_lower = _mm_cmpgt_epi32(second4, dist);
      if (_mm_movemask_epi8(_mm_or_si128(col_lower, row_lower)) == 0) continue;
      if (_mm_movemask_epi8(col_lower) != 0) {
        __m128i* const index4 = reinterpret_cast<__m128i*>(col_index + l);
        _mm_storeu_si128(best4, _mm_min_epi32(cols, dist));
        _mm_storeu_si128(index4, _mm_blendv_epi8(_mm_loadu_si128(index4), row_index, col_lower));
      }
      if (_mm_movemask_epi8(row_lower) != 0) {
        alignas(16) int four[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(four), dist);
        for (int i = 0; i < 4; ++i) update(r, four[i], int(l) + i);
        second4 = _mm_set1_epi32(r.second);
      }
    }
    for (std::size_t l = nb & ~std::size_t(3); l < nb; ++l) {
      const int dist = distance(a[k], b[l]);
      update(r, dist, int(l));
      if (dist < col_best[l]) {
        col_best[l] = dist;
        col_index[l] = int(k);
      }
    }
    rows[k] = r;
  }
}

}  // namespace plumb::descriptor_scan_avx2
#endif
