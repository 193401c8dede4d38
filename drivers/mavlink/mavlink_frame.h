#pragma once
// MAVLink v2 framing (unsigned frames only):
//
//   byte 0      STX 0xFD
//   byte 1      payload length after truncation
//   byte 2      incompatibility flags (0: not signed)
//   byte 3      compatibility flags (0)
//   byte 4      sequence number (wraps at 256; receivers count gaps as loss)
//   byte 5      system id
//   byte 6      component id
//   bytes 7-9   message id, 24 bits little-endian
//   payload     fields in wire order (largest type first, extensions last), little-endian
//   2 bytes     CRC-16/MCRF4XX over bytes 1..end of payload, then the message's CRC_EXTRA byte
//
// v2 truncation: trailing zero bytes of the payload are not sent (the receiver zero-fills), but
// at least one payload byte always is.
#include <cstddef>
#include <cstdint>

namespace plumb {

constexpr uint8_t kMavlinkV2Stx = 0xFD;
constexpr std::size_t kMavlinkV2HeaderBytes = 10;  // STX .. msgid
constexpr std::size_t kMavlinkV2CrcBytes = 2;
constexpr std::size_t kMavlinkMaxPayloadBytes = 255;
constexpr std::size_t kMavlinkV2MaxFrameBytes =
    kMavlinkV2HeaderBytes + kMavlinkMaxPayloadBytes + kMavlinkV2CrcBytes;

struct MavlinkFrameHeader {
  uint8_t sequence = 0;
  uint8_t system_id = 1;
  uint8_t component_id = 0;
  uint32_t message_id = 0;  // 24 bits used
};

// Length of `payload` once its trailing zeros are cut (never less than 1).
std::size_t mavlinkTruncatedPayloadLength(const uint8_t* payload, std::size_t size);

// Writes one complete v2 frame into out (capacity kMavlinkV2MaxFrameBytes) and returns its size.
// payload_size must be <= kMavlinkMaxPayloadBytes.
std::size_t writeMavlinkV2Frame(const MavlinkFrameHeader& header, uint8_t crc_extra, const uint8_t* payload,
                                std::size_t payload_size, uint8_t* out);

}  // namespace plumb
