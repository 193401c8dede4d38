#include "drivers/mavlink/mavlink_crc.h"

namespace plumb {

// Bytewise form of the reflected CCITT update (no table: a frame is a few hundred bytes).
uint16_t mavlinkCrcAccumulate(uint16_t crc, uint8_t byte) {
  uint8_t tmp = static_cast<uint8_t>(byte ^ static_cast<uint8_t>(crc & 0xFFu));
  tmp = static_cast<uint8_t>(tmp ^ static_cast<uint8_t>(tmp << 4));
  return static_cast<uint16_t>((crc >> 8) ^ (static_cast<uint16_t>(tmp) << 8) ^
                               (static_cast<uint16_t>(tmp) << 3) ^ (tmp >> 4));
}

uint16_t mavlinkCrcAccumulate(uint16_t crc, const uint8_t* data, std::size_t size) {
  for (std::size_t i = 0; i < size; ++i) crc = mavlinkCrcAccumulate(crc, data[i]);
  return crc;
}

}  // namespace plumb
