#include "drivers/mavlink/mavlink_frame.h"

#include <cstring>

#include "drivers/mavlink/mavlink_crc.h"

namespace plumb {

std::size_t mavlinkTruncatedPayloadLength(const uint8_t* payload, std::size_t size) {
  while (size > 1 && payload[size - 1] == 0) --size;
  return size;
}

std::size_t writeMavlinkV2Frame(const MavlinkFrameHeader& header, uint8_t crc_extra, const uint8_t* payload,
                                std::size_t payload_size, uint8_t* out) {
  const std::size_t length = mavlinkTruncatedPayloadLength(payload, payload_size);
  out[0] = kMavlinkV2Stx;
  out[1] = static_cast<uint8_t>(length);
  out[2] = 0;  // incompatibility flags: unsigned
  out[3] = 0;  // compatibility flags
  out[4] = header.sequence;
  out[5] = header.system_id;
  out[6] = header.component_id;
  out[7] = static_cast<uint8_t>(header.message_id & 0xFFu);
  out[8] = static_cast<uint8_t>((header.message_id >> 8) & 0xFFu);
  out[9] = static_cast<uint8_t>((header.message_id >> 16) & 0xFFu);
  std::memcpy(out + kMavlinkV2HeaderBytes, payload, length);
  uint16_t crc = mavlinkCrc(out + 1, kMavlinkV2HeaderBytes - 1 + length);
  crc = mavlinkCrcAccumulate(crc, crc_extra);
  out[kMavlinkV2HeaderBytes + length] = static_cast<uint8_t>(crc & 0xFFu);
  out[kMavlinkV2HeaderBytes + length + 1] = static_cast<uint8_t>(crc >> 8);
  return kMavlinkV2HeaderBytes + length + kMavlinkV2CrcBytes;
}

}  // namespace plumb
