#pragma once
// Nearest-neighbour matching of binary descriptors with Lowe's ratio test, the one used wherever a
// descriptor is matched against a set without a geometric prior: loop verification (query keyframe
// against candidate, pipeline/loop/loop_verifier.cpp) and relocalization (frame against a stored
// keyframe, pipeline/odometry/relocalizer.cpp). Tracking matches by projection instead
// (pipeline/odometry/), where the search window already rules most lookalikes out.
#include <cstddef>

#include "pipeline/frontend/frame_features.h"

namespace plumb {

// The two descriptors of others[0, n) nearest to d (Hamming distance; the first on ties): index -1
// and distance 256 where there is none.
struct NearestTwo {
  int best_index = -1, second_index = -1;
  int best = 256, second = 256;
};

inline NearestTwo nearestTwo(const Descriptor256& d, const Descriptor256* others, std::size_t n) {
  NearestTwo r;
  for (std::size_t j = 0; j < n; ++j) {
    const int dist = hammingDistance(d, others[j]);
    if (dist < r.best) {
      r.second = r.best;
      r.second_index = r.best_index;
      r.best = dist;
      r.best_index = int(j);
    } else if (dist < r.second) {
      r.second = dist;
      r.second_index = int(j);
    }
  }
  return r;
}

// True when the nearest is clearly better than the runner-up (best < ratio * second best).
inline bool passesRatio(const NearestTwo& r, float ratio) { return float(r.best) < ratio * float(r.second); }

// Index in [0, n) of the descriptor nearest to d (Hamming distance; the first on ties) when it is
// within max_distance bits AND clearly better than the runner-up (best < ratio * second best);
// -1 otherwise. Repeated texture gives near-equal best and second best: without geometry, no
// match is better than a coin toss between them.
inline int bestRatioMatch(const Descriptor256& d, const Descriptor256* others, std::size_t n, int max_distance,
                          float ratio) {
  const NearestTwo r = nearestTwo(d, others, n);
  if (r.best_index < 0 || r.best > max_distance || !passesRatio(r, ratio)) return -1;
  return r.best_index;
}

}  // namespace plumb
