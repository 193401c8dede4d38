// MAVLink v2 framing and message layout, checked against values derived from the spec here.
#include "drivers/mavlink/mavlink_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "drivers/mavlink/mavlink_crc.h"
#include "drivers/mavlink/mavlink_messages.h"
#include "mavlink_test_decoder.h"

namespace plumb {
namespace {

using namespace mavtest;

TEST(MavlinkCrc, StandardCheckValue) {
  // The catalogue check value of CRC-16/MCRF4XX over the ASCII digits "123456789".
  const char* digits = "123456789";
  EXPECT_EQ(mavlinkCrc(reinterpret_cast<const uint8_t*>(digits), 9), 0x6F91);
  uint16_t bitwise = 0xFFFF;
  for (int i = 0; i < 9; ++i) bitwise = crcBitwise(bitwise, static_cast<uint8_t>(digits[i]));
  EXPECT_EQ(bitwise, 0x6F91);
}

TEST(MavlinkCrc, ByteFormulaEqualsBitwiseOnAllBytes) {
  for (int start : {0x0000, 0xFFFF, 0x1234, 0xBEEF}) {
    for (int b = 0; b < 256; ++b) {
      ASSERT_EQ(mavlinkCrcAccumulate(static_cast<uint16_t>(start), static_cast<uint8_t>(b)),
                crcBitwise(static_cast<uint16_t>(start), static_cast<uint8_t>(b)));
    }
  }
}

TEST(MavlinkMessages, CrcExtraAndLengthsFromDefinitions) {
  EXPECT_EQ(crcExtra("HEARTBEAT", heartbeatDefinition()), kMavlinkCrcExtraHeartbeat);
  EXPECT_EQ(crcExtra("ODOMETRY", odometryDefinition()), kMavlinkCrcExtraOdometry);
  EXPECT_EQ(kMavlinkCrcExtraHeartbeat, 50);
  EXPECT_EQ(kMavlinkCrcExtraOdometry, 91);
  EXPECT_EQ(payloadBytes(heartbeatDefinition(), true), static_cast<int>(kMavlinkHeartbeatPayloadBytes));
  EXPECT_EQ(payloadBytes(odometryDefinition(), false), static_cast<int>(kMavlinkOdometryBasePayloadBytes));
  EXPECT_EQ(payloadBytes(odometryDefinition(), true), static_cast<int>(kMavlinkOdometryPayloadBytes));
}

// HEARTBEAT from sysid 1, compid 197, seq 0, worked out by hand from the spec:
//   header  FD 09 00 00 00 01 C5 00 00 00   (len 9, flags 0, seq 0, sys 1, comp 197, msgid 0)
//   payload 00 00 00 00 | 12 | 08 | 00 | 04 | 03
//           custom_mode 0, type 18 ONBOARD_CONTROLLER, autopilot 8 INVALID, base_mode 0,
//           system_status 4 ACTIVE, mavlink_version 3 (last byte non-zero: nothing truncated)
//   crc     0xE41E over bytes 1..18 then CRC_EXTRA 50, low byte first: 1E E4
//           (the same value from the bitwise CRC below and from node-mavlink's x25crc)
TEST(MavlinkFrame, HeartbeatReferenceBytes) {
  const uint8_t expected[] = {0xFD, 0x09, 0x00, 0x00, 0x00, 0x01, 0xC5, 0x00, 0x00, 0x00, 0x00,
                              0x00, 0x00, 0x00, 0x12, 0x08, 0x00, 0x04, 0x03, 0x1E, 0xE4};
  uint16_t crc = 0xFFFF;
  for (int i = 1; i <= 18; ++i) crc = crcBitwise(crc, expected[i]);
  crc = crcBitwise(crc, 50);
  ASSERT_EQ(crc, 0xE41E);

  MavlinkHeartbeat heartbeat;  // defaults: onboard controller, autopilot invalid, active
  uint8_t payload[kMavlinkHeartbeatPayloadBytes];
  packHeartbeatPayload(heartbeat, payload);
  MavlinkFrameHeader header;
  header.sequence = 0;
  header.system_id = 1;
  header.component_id = kMavCompIdVisualInertialOdometry;
  header.message_id = kMavlinkMsgIdHeartbeat;
  uint8_t frame[kMavlinkV2MaxFrameBytes];
  const std::size_t size =
      writeMavlinkV2Frame(header, kMavlinkCrcExtraHeartbeat, payload, sizeof(payload), frame);
  ASSERT_EQ(size, sizeof(expected));
  for (std::size_t i = 0; i < size; ++i) EXPECT_EQ(frame[i], expected[i]) << "byte " << i;
}

TEST(MavlinkFrame, TruncatesTrailingZerosButKeepsOneByte) {
  uint8_t payload[9] = {0};
  MavlinkFrameHeader header;
  header.message_id = 0x030201;  // 24-bit id, little-endian on the wire
  uint8_t frame[kMavlinkV2MaxFrameBytes];
  std::size_t size = writeMavlinkV2Frame(header, 7, payload, sizeof(payload), frame);
  EXPECT_EQ(frame[1], 1);  // all zero: one byte still sent
  EXPECT_EQ(size, 13u);
  EXPECT_EQ(frame[7], 0x01);
  EXPECT_EQ(frame[8], 0x02);
  EXPECT_EQ(frame[9], 0x03);
  payload[4] = 5;
  size = writeMavlinkV2Frame(header, 7, payload, sizeof(payload), frame);
  EXPECT_EQ(frame[1], 5);
  DecodedFrame decoded;
  ASSERT_TRUE(decodeFrame(frame, size, 7, &decoded));
  EXPECT_TRUE(decoded.crc_ok);
  EXPECT_EQ(decoded.msgid, 0x030201u);
  EXPECT_EQ(decoded.payload[4], 5);
  // A wrong CRC_EXTRA (a receiver with another layout) must reject the frame.
  ASSERT_TRUE(decodeFrame(frame, size, 8, &decoded));
  EXPECT_FALSE(decoded.crc_ok);
}

TEST(MavlinkMessages, OdometryFieldsAtSpecOffsets) {
  MavlinkOdometry m;
  m.time_usec = 0x0102030405060708ull;
  m.x = 1.5f;
  m.y = -2.25f;
  m.z = 3.125f;
  const float q[4] = {0.5f, -0.5f, 0.25f, -0.75f};
  std::memcpy(m.q, q, sizeof(q));
  m.vx = 4.f;
  m.vy = 5.f;
  m.vz = 6.f;
  m.rollspeed = 7.f;
  m.pitchspeed = 8.f;
  m.yawspeed = 9.f;
  for (int i = 0; i < 21; ++i) {
    m.pose_covariance[i] = 100.f + static_cast<float>(i);
    m.velocity_covariance[i] = 200.f + static_cast<float>(i);
  }
  m.frame_id = kMavFrameLocalFrd;
  m.child_frame_id = kMavFrameBodyFrd;
  m.reset_counter = 17;
  m.estimator_type = kMavEstimatorTypeVision;
  m.quality = -1;
  uint8_t p[kMavlinkOdometryPayloadBytes];
  std::memset(p, 0xAA, sizeof(p));
  packOdometryPayload(m, p);

  const auto def = odometryDefinition();
  auto at = [&](const char* name) { return fieldOffset(def, name); };
  EXPECT_EQ(readU64(p, at("time_usec")), m.time_usec);
  EXPECT_EQ(readFloat(p, at("x")), 1.5f);
  EXPECT_EQ(readFloat(p, at("y")), -2.25f);
  EXPECT_EQ(readFloat(p, at("z")), 3.125f);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(readFloat(p, at("q") + 4 * i), q[i]);
  EXPECT_EQ(readFloat(p, at("vx")), 4.f);
  EXPECT_EQ(readFloat(p, at("vy")), 5.f);
  EXPECT_EQ(readFloat(p, at("vz")), 6.f);
  EXPECT_EQ(readFloat(p, at("rollspeed")), 7.f);
  EXPECT_EQ(readFloat(p, at("pitchspeed")), 8.f);
  EXPECT_EQ(readFloat(p, at("yawspeed")), 9.f);
  for (int i = 0; i < 21; ++i) {
    EXPECT_EQ(readFloat(p, at("pose_covariance") + 4 * i), 100.f + i);
    EXPECT_EQ(readFloat(p, at("velocity_covariance") + 4 * i), 200.f + i);
  }
  EXPECT_EQ(p[at("frame_id")], 20);
  EXPECT_EQ(p[at("child_frame_id")], 12);
  EXPECT_EQ(p[at("reset_counter")], 17);
  EXPECT_EQ(p[at("estimator_type")], 2);
  EXPECT_EQ(static_cast<int8_t>(p[at("quality")]), -1);
  EXPECT_EQ(at("quality"), 232);
}

TEST(MavlinkMessages, HeartbeatFieldsAtSpecOffsets) {
  MavlinkHeartbeat h;
  h.custom_mode = 0xA1B2C3D4u;
  h.type = 11;
  h.autopilot = 22;
  h.base_mode = 33;
  h.system_status = 44;
  h.mavlink_version = 55;
  uint8_t p[kMavlinkHeartbeatPayloadBytes];
  packHeartbeatPayload(h, p);
  const auto def = heartbeatDefinition();
  const int cm = fieldOffset(def, "custom_mode");
  EXPECT_EQ(p[cm] | (p[cm + 1] << 8) | (p[cm + 2] << 16) | (static_cast<uint32_t>(p[cm + 3]) << 24),
            0xA1B2C3D4u);
  EXPECT_EQ(p[fieldOffset(def, "type")], 11);
  EXPECT_EQ(p[fieldOffset(def, "autopilot")], 22);
  EXPECT_EQ(p[fieldOffset(def, "base_mode")], 33);
  EXPECT_EQ(p[fieldOffset(def, "system_status")], 44);
  EXPECT_EQ(p[fieldOffset(def, "mavlink_version")], 55);
}

}  // namespace
}  // namespace plumb
