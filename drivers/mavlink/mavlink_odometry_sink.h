#pragma once
// MavlinkOdometrySink: sends plumb's poses to an autopilot as MAVLink v2 ODOMETRY (#331) plus a
// HEARTBEAT (#0) every heartbeat_period_s, as a visual odometry component. Built for the frame
// loop: publish() never blocks (non-blocking UDP / serial, frames that would block are dropped and
// counted) and allocates nothing (fixed member buffers); only open() allocates.
//
//   MavlinkOptions options;
//   options.endpoint = "udp:127.0.0.1:14540";
//   MavlinkOdometrySink sink;
//   PLUMB_RETURN_IF_ERROR(sink.open(options));
//   for each frame: sink.publish(sample);            // OdometrySample from the odometry result
//   sink.stats();                                    // sent / dropped / bytes
//
// Frames, covariance and field semantics: drivers/mavlink/odometry_frames.h, docs/MAVLINK.md.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "drivers/mavlink/mavlink_frame.h"
#include "drivers/mavlink/mavlink_messages.h"
#include "drivers/mavlink/mavlink_transport.h"
#include "drivers/mavlink/odometry_frames.h"
#include "platform/status.h"
#include "solver/types.h"

namespace plumb {

struct MavlinkOptions {
  std::string endpoint;  // "udp:HOST:PORT" or "serial:DEVICE:BAUD" (mavlink_endpoint.h)
  // Same system id as the autopilot (1 on a default PX4/ArduPilot), our own component id.
  uint8_t system_id = 1;
  uint8_t component_id = kMavCompIdVisualInertialOdometry;
  // Camera -> body (FRD). Default: forward-looking camera at the body origin.
  Eigen::Isometry3d T_body_cam = forwardCameraBodyFrdExtrinsic();
  // plumb world -> MAVLink local frame. Default (use_T_local_world false): T_local_world =
  // T_body_cam, i.e. the local frame is the body frame when the camera was at plumb's world origin
  // (plumb's world is the first camera frame), so the vehicle starts at 0 facing +x.
  bool use_T_local_world = false;
  Eigen::Isometry3d T_local_world = Eigen::Isometry3d::Identity();
  // kMavFrameLocalFrd (default: heading is the vehicle's at start) or kMavFrameLocalNed (the user
  // asserts the vehicle started level and facing north, or the autopilot rotates the frame).
  uint8_t frame_id = kMavFrameLocalFrd;
  uint8_t estimator_type = kMavEstimatorTypeVision;  // RGB-D odometry, no IMU
  double heartbeat_period_s = 1.0;                   // <= 0 disables the heartbeat
  // The first pose after start, a reset or a lost stretch has no velocity (it needs two poses).
  // true: that pose is not sent (counted in skipped_unknown_velocity), so every ODOMETRY carries a
  // finite velocity; ArduPilot's ODOMETRY handler passes vx, vy, vz to its EKF without a NaN
  // check. false: it is sent with NaN velocity and rates, as MAVLink allows (PX4 ignores them).
  bool hold_until_velocity_known = true;
};

// One odometry result, as the frame loop has it.
struct OdometrySample {
  double timestamp_s = 0.0;  // sensor time of the frame (seconds; sent as microseconds)
  bool has_pose = false;     // false while lost: nothing is sent for this frame
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  int tracking_quality = 0;  // 0 (unknown) .. 100 (best), from the tracking state
  bool has_covariance = false;
  Matrix6d covariance = Matrix6d::Zero();  // of delta = [rho; phi] of T_cam_world (solver/se3.h)
  // The pose's covariance relative to the map (TrackResult::covariance_local): the velocity
  // covariance is built from this one of two consecutive samples.
  bool has_local_covariance = false;
  Matrix6d local_covariance = Matrix6d::Zero();
  bool reset = false;  // the estimate jumped (new map segment, loop correction): reset_counter++
  // The previous frame's pose in the map this one was tracked in (TrackResult::T_world_previous):
  // when set and it is the previous sample's frame (same timestamp), the velocity is the motion
  // from it, so a map update between the two frames (local BA, a loop) is not sent as velocity.
  // Unset: the velocity is the difference of the two published poses.
  bool has_previous_in_map = false;
  double previous_timestamp_s = 0.0;
  Eigen::Isometry3d T_world_previous_cam = Eigen::Isometry3d::Identity();
};

struct MavlinkStats {
  uint64_t odometry_sent = 0;
  uint64_t heartbeats_sent = 0;
  uint64_t dropped = 0;  // frames the transport could not take (would block / error)
  uint64_t bytes_sent = 0;
  uint64_t skipped_no_pose = 0;           // samples with has_pose == false
  uint64_t skipped_unknown_velocity = 0;  // held back by hold_until_velocity_known
  uint64_t resets = 0;                    // reset_counter increments
};

class MavlinkOdometrySink {
 public:
  Status open(const MavlinkOptions& options);
  bool isOpen() const { return transport_.isOpen(); }

  // Sends a heartbeat when one is due, then the ODOMETRY message of the sample (if it has a pose).
  void publish(const OdometrySample& sample);
  void publish(const OdometrySample& sample, int64_t now_ns);  // explicit monotonic time (tests)
  // Keeps the heartbeat going when no frames arrive (e.g. a stalled camera).
  void sendHeartbeatIfDue(int64_t now_ns);

  // Fills the ODOMETRY fields of a sample without sending (what publish() would send). Updates
  // the velocity history and the reset counter exactly as publish() does.
  void buildOdometry(const OdometrySample& sample, MavlinkOdometry* out);

  // The ODOMETRY fields of the last sample with a pose (sent, dropped or held), e.g. to log them.
  const MavlinkOdometry& lastOdometry() const { return last_odometry_; }
  const MavlinkStats& stats() const { return stats_; }
  const MavlinkOptions& options() const { return options_; }

 private:
  bool sendMessage(uint32_t message_id, uint8_t crc_extra, const uint8_t* payload, std::size_t payload_size);

  MavlinkOptions options_;
  MavlinkFrameChange frames_;
  MavlinkTransport transport_;
  MavlinkStats stats_;
  MavlinkOdometry last_odometry_;
  uint8_t sequence_ = 0;
  uint8_t reset_counter_ = 0;
  bool last_had_pose_ = false;
  int64_t next_heartbeat_ns_ = 0;
  bool has_previous_ = false;
  double previous_time_s_ = 0.0;
  Eigen::Isometry3d previous_T_world_cam_ = Eigen::Isometry3d::Identity();
  bool previous_has_local_covariance_ = false;
  Matrix6d previous_local_covariance_ = Matrix6d::Zero();
  uint8_t payload_[kMavlinkMaxPayloadBytes] = {};
  uint8_t frame_[kMavlinkV2MaxFrameBytes] = {};
};

}  // namespace plumb
