#pragma once
// The two MAVLink messages plumb sends, written from the definitions in MAVLink's
// message_definitions/v1.0 (minimal.xml: HEARTBEAT; common.xml: ODOMETRY) - no generated headers.
//
// Wire order: base fields sorted by type size, largest first (stable among equal sizes), then the
// extension fields in declaration order. CRC_EXTRA hashes the base fields only (see
// docs/MAVLINK.md; tests/drivers/mavlink recomputes both values from the field lists).
//
//   HEARTBEAT #0, 9 bytes, CRC_EXTRA 50
//     0 custom_mode uint32 | 4 type | 5 autopilot | 6 base_mode | 7 system_status |
//     8 mavlink_version (all uint8)
//   ODOMETRY #331, 230 bytes base + 3 extension bytes = 233, CRC_EXTRA 91
//     0 time_usec uint64 | 8 x | 12 y | 16 z | 20 q[4] | 36 vx | 40 vy | 44 vz | 48 rollspeed |
//     52 pitchspeed | 56 yawspeed | 60 pose_covariance[21] | 144 velocity_covariance[21] (floats) |
//     228 frame_id | 229 child_frame_id (uint8) | extensions: 230 reset_counter uint8 |
//     231 estimator_type uint8 | 232 quality int8
#include <cstddef>
#include <cstdint>

namespace plumb {

constexpr uint32_t kMavlinkMsgIdHeartbeat = 0;
constexpr uint8_t kMavlinkCrcExtraHeartbeat = 50;
constexpr std::size_t kMavlinkHeartbeatPayloadBytes = 9;

constexpr uint32_t kMavlinkMsgIdOdometry = 331;
constexpr uint8_t kMavlinkCrcExtraOdometry = 91;
constexpr std::size_t kMavlinkOdometryBasePayloadBytes = 230;
constexpr std::size_t kMavlinkOdometryPayloadBytes = 233;

// Enum values used (minimal.xml / common.xml).
constexpr uint8_t kMavTypeOnboardController = 18;          // MAV_TYPE_ONBOARD_CONTROLLER
constexpr uint8_t kMavAutopilotInvalid = 8;                // MAV_AUTOPILOT_INVALID: not a flight stack
constexpr uint8_t kMavStateActive = 4;                     // MAV_STATE_ACTIVE
constexpr uint8_t kMavStateCritical = 5;                   // MAV_STATE_CRITICAL (tracking lost)
constexpr uint8_t kMavlinkProtocolVersion = 3;             // HEARTBEAT.mavlink_version
constexpr uint8_t kMavCompIdVisualInertialOdometry = 197;  // MAV_COMP_ID_VISUAL_INERTIAL_ODOMETRY
constexpr uint8_t kMavFrameLocalNed = 1;                   // MAV_FRAME_LOCAL_NED
constexpr uint8_t kMavFrameBodyFrd = 12;                   // MAV_FRAME_BODY_FRD
constexpr uint8_t kMavFrameLocalFrd = 20;                  // MAV_FRAME_LOCAL_FRD
constexpr uint8_t kMavEstimatorTypeVision = 2;             // MAV_ESTIMATOR_TYPE_VISION
constexpr uint8_t kMavEstimatorTypeVio = 3;                // MAV_ESTIMATOR_TYPE_VIO

struct MavlinkHeartbeat {
  uint32_t custom_mode = 0;
  uint8_t type = kMavTypeOnboardController;
  uint8_t autopilot = kMavAutopilotInvalid;
  uint8_t base_mode = 0;
  uint8_t system_status = kMavStateActive;
  uint8_t mavlink_version = kMavlinkProtocolVersion;
};

// ODOMETRY fields as the message defines them. Covariances: row-major upper-right triangle of a
// 6x6 matrix (21 values); NaN in element 0 means unknown.
struct MavlinkOdometry {
  uint64_t time_usec = 0;
  float x = 0.f, y = 0.f, z = 0.f;
  float q[4] = {1.f, 0.f, 0.f, 0.f};  // w, x, y, z: rotation body -> frame_id frame
  float vx = 0.f, vy = 0.f, vz = 0.f;
  float rollspeed = 0.f, pitchspeed = 0.f, yawspeed = 0.f;
  float pose_covariance[21] = {};
  float velocity_covariance[21] = {};
  uint8_t frame_id = kMavFrameLocalFrd;
  uint8_t child_frame_id = kMavFrameBodyFrd;
  uint8_t reset_counter = 0;
  uint8_t estimator_type = kMavEstimatorTypeVision;
  int8_t quality = 0;  // -1 failed, 0 unknown, 1 worst .. 100 best
};

// Serialise into the full (untruncated) little-endian payload; out must hold the *PayloadBytes.
void packHeartbeatPayload(const MavlinkHeartbeat& message, uint8_t* out);
void packOdometryPayload(const MavlinkOdometry& message, uint8_t* out);

}  // namespace plumb
