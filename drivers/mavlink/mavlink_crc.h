#pragma once
// CRC-16/MCRF4XX, the checksum of every MAVLink frame (the MAVLink docs call it "X.25 CRC"):
// polynomial 0x1021 reflected (0x8408), init 0xFFFF, no final xor. A frame's CRC runs over the
// header after the start byte, the payload, then one "CRC_EXTRA" byte per message that hashes the
// message definition, so a sender and receiver that disagree on a message's layout reject it.
#include <cstddef>
#include <cstdint>

namespace plumb {

constexpr uint16_t kMavlinkCrcInit = 0xFFFFu;

// Folds one byte into the running CRC.
uint16_t mavlinkCrcAccumulate(uint16_t crc, uint8_t byte);
uint16_t mavlinkCrcAccumulate(uint16_t crc, const uint8_t* data, std::size_t size);
inline uint16_t mavlinkCrc(const uint8_t* data, std::size_t size) {
  return mavlinkCrcAccumulate(kMavlinkCrcInit, data, size);
}

}  // namespace plumb
