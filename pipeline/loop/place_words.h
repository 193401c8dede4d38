#pragma once
// Visual words without a trained vocabulary: a word is the value of K fixed bits of a 256-bit
// binary descriptor (ORB's rotated BRIEF or our LBD code), as in Basalt's hash bag of words.
//
// Why this works: two observations of the same 3D point or line give descriptors a few tens of
// bits apart (out of 256), so with K = 16 a re-observed feature keeps its word with probability
// (1 - p)^16 (p = fraction of flipped bits: 0.37 at p = 0.06, 0.19 at p = 0.1), while two unrelated
// descriptors share a word with probability ~2^-16. Between two ~1000-descriptor views of the
// same place that is ~190-370 shared words against ~15 chance collisions.
//
// Why K = 16 (the default) rather than 12 or 20: 2^16 words cost 256 KiB of list heads per word
// space; K = 12 gives ~16x more chance collisions (a 1000 x 1000 pair shares ~240 words by
// chance), K = 20 needs 4 MiB of heads per space and keeps only (1 - p)^20 of the true words.
// One table (not several with different bits): several tables raise recall but multiply the
// posting memory; one is enough while views of a revisited place share hundreds of words.
//
// The bit positions are a fixed pseudo-random choice (a SplitMix64-driven shuffle of 0..255 with a
// constant seed), the same in every build, so a saved database stays valid.
#include <array>
#include <cstdint>

#include "pipeline/frontend/frame_features.h"

namespace plumb::loop {

constexpr int kMinWordBits = 8;
constexpr int kMaxWordBits = 20;
constexpr int kDefaultWordBits = 16;

// Descriptor families get separate word spaces: an ORB word and an LBD word with the same bit
// value are different words.
enum class DescriptorKind : uint8_t { kPoint = 0, kLine = 1 };

// The 256 bit indices in the fixed order the words take them from (first K of them make a word).
const std::array<uint8_t, 256>& wordBitOrder();

// The K-bit value of `d` (bit k of the result = bit wordBitOrder()[k] of the descriptor).
inline uint32_t descriptorWordValue(const Descriptor256& d, int bits_per_word) {
  const std::array<uint8_t, 256>& order = wordBitOrder();
  uint32_t value = 0;
  for (int k = 0; k < bits_per_word; ++k) {
    const int b = order[k];
    value |= static_cast<uint32_t>((d.words[b >> 6] >> (b & 63)) & 1u) << k;
  }
  return value;
}

// Word id across both spaces: kind in the bit above the K value bits.
inline uint32_t wordId(DescriptorKind kind, uint32_t value, int bits_per_word) {
  return (static_cast<uint32_t>(kind) << bits_per_word) | value;
}
inline DescriptorKind wordKind(uint32_t word_id, int bits_per_word) {
  return static_cast<DescriptorKind>(word_id >> bits_per_word);
}

// A word and how many descriptors of one keyframe fall in it (its term frequency).
struct WordCount {
  uint32_t word = 0;   // wordId(kind, value, bits)
  uint32_t count = 0;
};

}  // namespace plumb::loop
