#pragma once
// Nearest-neighbour matching of binary descriptors with Lowe's ratio test, the one used wherever a
// descriptor is matched against a set without a geometric prior: loop verification (query keyframe
// against candidate, pipeline/loop/loop_verifier.cpp) and relocalization (frame against a stored
// keyframe, pipeline/odometry/relocalizer.cpp). Tracking matches by projection instead
// (pipeline/odometry/), where the search window already rules most lookalikes out.
#include <cstddef>

#include "pipeline/frontend/frame_features.h"

namespace plumb {

// Index in [0, n) of the descriptor nearest to d (Hamming distance; the first on ties) when it is
// within max_distance bits AND clearly better than the runner-up (best < ratio * second best);
// -1 otherwise. Repeated texture gives near-equal best and second best: no match is better than a
// coin toss between them.
inline int bestRatioMatch(const Descriptor256& d, const Descriptor256* others, std::size_t n, int max_distance,
                          float ratio) {
  int best = 256, second = 256, best_index = -1;
  for (std::size_t j = 0; j < n; ++j) {
    const int dist = hammingDistance(d, others[j]);
    if (dist < best) {
      second = best;
      best = dist;
      best_index = int(j);
    } else if (dist < second) {
      second = dist;
    }
  }
  if (best_index < 0 || best > max_distance || float(best) >= ratio * float(second)) return -1;
  return best_index;
}

}  // namespace plumb
