#pragma once
// Nearest-neighbour matching of binary descriptors with Lowe's ratio test, the one used wherever a
// descriptor is matched against a set without a geometric prior: loop verification (query keyframe
// against candidate, pipeline/loop/loop_verifier.cpp), the loop's context check (every point of
// one keyframe against every point of another, both ways, pipeline/loop/loop_context_check.cpp)
// and relocalization (frame against a stored keyframe, pipeline/odometry/relocalizer.cpp).
// Tracking matches by projection instead (pipeline/odometry/), where the search window already
// rules most lookalikes out.
//
// The scans are brute force (every pair) and are the loop stage's main cost, so they live in
// descriptor_match.cpp with more than one build: x86-64's portable baseline has no POPCNT
// (hammingDistance is ~30 SSE2 instructions there), so on CPUs that have it (chosen at run time) a
// copy compiled for POPCNT counts each 64-bit word in one instruction, and one for AVX2 counts four
// descriptors at a time. All count the same bits and update in index order: the same results.
// docs/LOOP.md "Cost of the loop stage".
#include <cstddef>

#include "pipeline/frontend/frame_features.h"

namespace plumb {

// The two descriptors of others[0, n) nearest to d (Hamming distance; the first on ties): index -1
// and distance 256 where there is none.
struct NearestTwo {
  int best_index = -1, second_index = -1;
  int best = 256, second = 256;
};

// nearestTwo() with every distance >= bound treated as none: best and second are
// min(true value, bound), their indices -1 where the value is bound. Exactly nearestTwo() for
// bound = 256 (no Hamming distance of 256 bits is below it). A smaller bound lets the scan skip a
// descriptor as soon as the distance of its first words reaches the current second best (or
// bound): callers pass the smallest bound that cannot change their decision (ratioBound below).
// bound in [0, 257].
NearestTwo nearestTwoBelow(const Descriptor256& d, const Descriptor256* others, std::size_t n, int bound);

inline NearestTwo nearestTwo(const Descriptor256& d, const Descriptor256* others, std::size_t n) {
  return nearestTwoBelow(d, others, n, 256);
}

// True when the nearest is clearly better than the runner-up (best < ratio * second best).
inline bool passesRatio(const NearestTwo& r, float ratio) { return float(r.best) < ratio * float(r.second); }

// The smallest second-best distance c in [max_distance + 1, none) from which on every best within
// max_distance passes the ratio test: float(best) < ratio * float(c) for best <= max_distance, and
// so for every second best >= c (the product is monotonic in it). `none` where there is no such c.
// A match is decided by best <= max_distance and the ratio test alone, so scanning below this
// bound (nearestTwoBelow) decides every match exactly as the full scan: a best within max_distance
// is below the bound with its index, and a second best clamped to the bound passes the ratio test
// exactly when the true one does. It also keeps every second best within max_distance exact.
int ratioBound(int max_distance, float ratio, int none = 256);

// Index in [0, n) of the descriptor nearest to d (Hamming distance; the first on ties) when it is
// within max_distance bits AND clearly better than the runner-up (best < ratio * second best);
// -1 otherwise. Repeated texture gives near-equal best and second best: without geometry, no
// match is better than a coin toss between them.
inline int bestRatioMatch(const Descriptor256& d, const Descriptor256* others, std::size_t n, int max_distance,
                          float ratio) {
  const NearestTwo r = nearestTwoBelow(d, others, n, ratioBound(max_distance, ratio));
  if (r.best_index < 0 || r.best > max_distance || !passesRatio(r, ratio)) return -1;
  return r.best_index;
}

// Both directions between two sets in one pass over the pairs: rows[k] = nearestTwoBelow(a[k], b,
// nb, row_bound), and for every b[l] the nearest a below col_bound: col_best[l] =
// min(distance, col_bound), col_index[l] its index (the first on ties) or -1. rows has na
// entries, col_best and col_index nb. Bounds in [0, 257].
void nearestBothWays(const Descriptor256* a, std::size_t na, const Descriptor256* b, std::size_t nb, int row_bound,
                     int col_bound, NearestTwo* rows, int* col_best, int* col_index);

// The builds of the scans: kPortable runs everywhere; on x86-64 without -mpopcnt, kPopcnt (POPCNT
// word counts) and kAvx2 (four descriptors at a time, descriptor_match_avx2.cpp) where the CPU has
// them. The scans above use the fastest available one (descriptorScanPath()); the *On variants
// run a given one, for tests to compare them (an unavailable one runs kPortable).
enum class DescriptorScanPath { kPortable, kPopcnt, kAvx2 };
bool descriptorScanAvailable(DescriptorScanPath path);
DescriptorScanPath descriptorScanPath();
NearestTwo nearestTwoBelowOn(DescriptorScanPath path, const Descriptor256& d, const Descriptor256* others,
                             std::size_t n, int bound);
void nearestBothWaysOn(DescriptorScanPath path, const Descriptor256* a, std::size_t na, const Descriptor256* b,
                       std::size_t nb, int row_bound, int col_bound, NearestTwo* rows, int* col_best, int* col_index);

}  // namespace plumb
