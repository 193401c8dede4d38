#include "drivers/mavlink/mavlink_messages.h"

#include <cstring>

namespace plumb {
namespace {

// Explicit little-endian stores, so the wire format does not depend on the host's byte order.
void putU8(uint8_t* out, std::size_t offset, uint8_t v) { out[offset] = v; }

void putU32(uint8_t* out, std::size_t offset, uint32_t v) {
  for (int i = 0; i < 4; ++i) out[offset + i] = static_cast<uint8_t>(v >> (8 * i));
}

void putU64(uint8_t* out, std::size_t offset, uint64_t v) {
  for (int i = 0; i < 8; ++i) out[offset + i] = static_cast<uint8_t>(v >> (8 * i));
}

void putFloat(uint8_t* out, std::size_t offset, float v) {
  uint32_t bits;
  static_assert(sizeof(bits) == sizeof(v), "IEEE-754 single expected");
  std::memcpy(&bits, &v, sizeof(bits));
  putU32(out, offset, bits);
}

void putFloats(uint8_t* out, std::size_t offset, const float* v, int count) {
  for (int i = 0; i < count; ++i) putFloat(out, offset + 4 * static_cast<std::size_t>(i), v[i]);
}

}  // namespace

void packHeartbeatPayload(const MavlinkHeartbeat& m, uint8_t* out) {
  putU32(out, 0, m.custom_mode);
  putU8(out, 4, m.type);
  putU8(out, 5, m.autopilot);
  putU8(out, 6, m.base_mode);
  putU8(out, 7, m.system_status);
  putU8(out, 8, m.mavlink_version);
}

void packOdometryPayload(const MavlinkOdometry& m, uint8_t* out) {
  putU64(out, 0, m.time_usec);
  putFloat(out, 8, m.x);
  putFloat(out, 12, m.y);
  putFloat(out, 16, m.z);
  putFloats(out, 20, m.q, 4);
  putFloat(out, 36, m.vx);
  putFloat(out, 40, m.vy);
  putFloat(out, 44, m.vz);
  putFloat(out, 48, m.rollspeed);
  putFloat(out, 52, m.pitchspeed);
  putFloat(out, 56, m.yawspeed);
  putFloats(out, 60, m.pose_covariance, 21);
  putFloats(out, 144, m.velocity_covariance, 21);
  putU8(out, 228, m.frame_id);
  putU8(out, 229, m.child_frame_id);
  // Extensions (MAVLink 2 only), in declaration order.
  putU8(out, 230, m.reset_counter);
  putU8(out, 231, m.estimator_type);
  putU8(out, 232, static_cast<uint8_t>(m.quality));
}

}  // namespace plumb
