#pragma once
// Test-side MAVLink reader, written separately from drivers/mavlink so the tests do not check the
// encoder against itself: a bit-by-bit CRC (not the byte formula the encoder uses), field offsets
// derived from the message definitions by MAVLink's sort rule, and a frame parser.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace plumb {
namespace mavtest {

// CRC-16/MCRF4XX one bit at a time: reflected polynomial 0x8408, init 0xFFFF.
inline uint16_t crcBitwise(uint16_t crc, uint8_t byte) {
  crc ^= byte;
  for (int bit = 0; bit < 8; ++bit)
    crc = (crc & 1u) ? static_cast<uint16_t>((crc >> 1) ^ 0x8408u) : static_cast<uint16_t>(crc >> 1);
  return crc;
}
inline uint16_t crcBitwise(uint16_t crc, const std::string& text) {
  for (unsigned char c : text) crc = crcBitwise(crc, static_cast<uint8_t>(c));
  return crc;
}

// A field as declared in the XML (declaration order, extensions flagged).
struct FieldDef {
  std::string type;  // "uint64_t", "float", "uint8_t", "int8_t", "uint32_t"
  std::string name;
  int array_length;  // 0 = scalar
  bool extension;
};

inline int typeSize(const std::string& type) {
  if (type == "uint64_t" || type == "int64_t" || type == "double") return 8;
  if (type == "uint32_t" || type == "int32_t" || type == "float") return 4;
  if (type == "uint16_t" || type == "int16_t") return 2;
  return 1;
}

// Wire order: base fields stable-sorted by element size (largest first), extensions after them
// in declaration order.
inline std::vector<FieldDef> wireOrder(const std::vector<FieldDef>& declared) {
  std::vector<FieldDef> base, ext;
  for (const FieldDef& f : declared) (f.extension ? ext : base).push_back(f);
  std::stable_sort(base.begin(), base.end(),
                   [](const FieldDef& a, const FieldDef& b) { return typeSize(a.type) > typeSize(b.type); });
  base.insert(base.end(), ext.begin(), ext.end());
  return base;
}

inline int fieldOffset(const std::vector<FieldDef>& declared, const std::string& name) {
  int offset = 0;
  for (const FieldDef& f : wireOrder(declared)) {
    if (f.name == name) return offset;
    offset += typeSize(f.type) * std::max(1, f.array_length);
  }
  return -1;
}

inline int payloadBytes(const std::vector<FieldDef>& declared, bool with_extensions) {
  int total = 0;
  for (const FieldDef& f : declared) {
    if (!f.extension || with_extensions) total += typeSize(f.type) * std::max(1, f.array_length);
  }
  return total;
}

// CRC_EXTRA as MAVLink defines it: CRC of "NAME " then, per base field in wire order,
// "type " "name " and the array length byte for arrays; folded to 8 bits.
inline uint8_t crcExtra(const std::string& message_name, const std::vector<FieldDef>& declared) {
  uint16_t crc = crcBitwise(0xFFFF, message_name + " ");
  for (const FieldDef& f : wireOrder(declared)) {
    if (f.extension) continue;
    crc = crcBitwise(crc, f.type + " ");
    crc = crcBitwise(crc, f.name + " ");
    if (f.array_length > 0) crc = crcBitwise(crc, static_cast<uint8_t>(f.array_length));
  }
  return static_cast<uint8_t>((crc & 0xFFu) ^ (crc >> 8));
}

// common.xml / minimal.xml, declaration order.
inline std::vector<FieldDef> heartbeatDefinition() {
  return {{"uint8_t", "type", 0, false},          {"uint8_t", "autopilot", 0, false},
          {"uint8_t", "base_mode", 0, false},     {"uint32_t", "custom_mode", 0, false},
          {"uint8_t", "system_status", 0, false}, {"uint8_t", "mavlink_version", 0, false}};
}

inline std::vector<FieldDef> odometryDefinition() {
  return {{"uint64_t", "time_usec", 0, false},
          {"uint8_t", "frame_id", 0, false},
          {"uint8_t", "child_frame_id", 0, false},
          {"float", "x", 0, false},
          {"float", "y", 0, false},
          {"float", "z", 0, false},
          {"float", "q", 4, false},
          {"float", "vx", 0, false},
          {"float", "vy", 0, false},
          {"float", "vz", 0, false},
          {"float", "rollspeed", 0, false},
          {"float", "pitchspeed", 0, false},
          {"float", "yawspeed", 0, false},
          {"float", "pose_covariance", 21, false},
          {"float", "velocity_covariance", 21, false},
          {"uint8_t", "reset_counter", 0, true},
          {"uint8_t", "estimator_type", 0, true},
          {"int8_t", "quality", 0, true}};
}

struct DecodedFrame {
  bool crc_ok = false;
  uint8_t length = 0, seq = 0, sysid = 0, compid = 0;
  uint32_t msgid = 0;
  uint8_t payload[255] = {};  // zero-filled past `length` (v2 truncation)
  std::size_t frame_size = 0;
};

// Parses one frame at data[0]; returns false if it is not a complete v2 frame.
inline bool decodeFrame(const uint8_t* data, std::size_t size, uint8_t crc_extra, DecodedFrame* out) {
  if (size < 12 || data[0] != 0xFD) return false;
  const std::size_t len = data[1];
  if (size < 12 + len) return false;
  out->length = data[1];
  out->seq = data[4];
  out->sysid = data[5];
  out->compid = data[6];
  out->msgid = data[7] | (data[8] << 8) | (data[9] << 16);
  std::memset(out->payload, 0, sizeof(out->payload));
  std::memcpy(out->payload, data + 10, len);
  uint16_t crc = 0xFFFF;
  for (std::size_t i = 1; i < 10 + len; ++i) crc = crcBitwise(crc, data[i]);
  crc = crcBitwise(crc, crc_extra);
  out->crc_ok = (data[10 + len] == (crc & 0xFF)) && (data[11 + len] == (crc >> 8));
  out->frame_size = 12 + len;
  return true;
}

inline float readFloat(const uint8_t* p, int offset) {
  uint32_t bits = 0;
  for (int i = 0; i < 4; ++i) bits |= static_cast<uint32_t>(p[offset + i]) << (8 * i);
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}
inline uint64_t readU64(const uint8_t* p, int offset) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(p[offset + i]) << (8 * i);
  return v;
}

}  // namespace mavtest
}  // namespace plumb
