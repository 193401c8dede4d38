// The fixed bit order of the hash words (see place_words.h).
#include "pipeline/loop/place_words.h"

namespace plumb::loop {
namespace {

// SplitMix64 (Steele, Lea, Flood 2014): tiny, well mixed, identical on every platform.
uint64_t splitMix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::array<uint8_t, 256> makeBitOrder() {
  std::array<uint8_t, 256> order{};
  for (int i = 0; i < 256; ++i) order[i] = static_cast<uint8_t>(i);
  // Fisher-Yates with a constant seed: changing it would invalidate saved databases.
  uint64_t state = 0x506c756d62426f57ULL;  // "PlumbBoW"
  for (int i = 255; i > 0; --i) {
    const int j = static_cast<int>(splitMix64(state) % static_cast<uint64_t>(i + 1));
    const uint8_t t = order[i];
    order[i] = order[j];
    order[j] = t;
  }
  return order;
}

}  // namespace

const std::array<uint8_t, 256>& wordBitOrder() {
  static const std::array<uint8_t, 256> order = makeBitOrder();
  return order;
}

}  // namespace plumb::loop
