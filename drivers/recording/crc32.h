#pragma once
// CRC-32 (IEEE 802.3 polynomial, reflected, init/xorout 0xFFFFFFFF: the zlib / PNG CRC), used to
// check every chunk of a recording. Incremental: crc32Update(crc32Update(kCrc32Init, a), b) then
// crc32Finish() equals the CRC of a followed by b.
#include <cstddef>
#include <cstdint>

namespace plumb {

constexpr uint32_t kCrc32Init = 0xFFFFFFFFu;

uint32_t crc32Update(uint32_t state, const void* data, std::size_t size);
inline uint32_t crc32Finish(uint32_t state) { return state ^ 0xFFFFFFFFu; }
inline uint32_t crc32(const void* data, std::size_t size) {
  return crc32Finish(crc32Update(kCrc32Init, data, size));
}

}  // namespace plumb
