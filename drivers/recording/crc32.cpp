#include "drivers/recording/crc32.h"

#include <array>

namespace plumb {
namespace {

// Byte-at-a-time table for the reflected polynomial 0xEDB88320, built once at first use.
std::array<uint32_t, 256> makeTable() {
  std::array<uint32_t, 256> table{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  return table;
}

}  // namespace

uint32_t crc32Update(uint32_t state, const void* data, std::size_t size) {
  static const std::array<uint32_t, 256> kTable = makeTable();
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) state = kTable[(state ^ bytes[i]) & 0xFFu] ^ (state >> 8);
  return state;
}

}  // namespace plumb
