#pragma once
// Seeded randomness for the synthetic scenes, defined bit for bit by this file.
//
// std::uniform_*_distribution and std::normal_distribution are implementation-defined (libstdc++
// and libc++ give different numbers for the same engine), so the scenes use SplitMix64 for
// sequential draws (layout, colours, textures) and a counter-based hash for per-pixel noise: the
// noise of pixel p in frame i is hash(seed, i, p), independent of the order pixels are visited.
#include <cstdint>

namespace plumb::synth {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Hash of a (seed, stream, index) triple, for order-independent per-pixel noise.
inline uint64_t hash3(uint64_t seed, uint64_t stream, uint64_t index) {
  return mix64(mix64(seed ^ (stream * 0x9e3779b97f4a7c15ULL)) + index);
}

// Sequential generator for scene construction.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return mix64(state_);
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform integer in [lo, hi] (inclusive); the tiny modulo bias does not matter here.
  int uniformInt(int lo, int hi) {
    return lo + static_cast<int>(next() % static_cast<uint64_t>(hi - lo + 1));
  }
  // Standard normal via the 16-bit quantile table below (plenty for scene jitter).
  double gaussian();

 private:
  uint64_t state_;
};

// Standard normal quantiles at (k + 0.5) / 65536, k = 0..65535: a 16-bit uniform index gives a
// Gaussian sample (tails cut at ~4.3 sigma). One 64-bit hash yields four independent samples.
const float* gaussianQuantileTable();

inline float gaussianFromBits(uint64_t bits16) {
  return gaussianQuantileTable()[bits16 & 0xffffu];
}

inline double SplitMix64::gaussian() { return gaussianFromBits(next() >> 48); }

}  // namespace plumb::synth
