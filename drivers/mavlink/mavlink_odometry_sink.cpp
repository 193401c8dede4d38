#include "drivers/mavlink/mavlink_odometry_sink.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "platform/monotonic_time.h"
#include "solver/se3.h"

namespace plumb {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

}  // namespace

Status MavlinkOdometrySink::open(const MavlinkOptions& options) {
  MavlinkEndpoint endpoint;
  PLUMB_RETURN_IF_ERROR(parseMavlinkEndpoint(options.endpoint, &endpoint));
  if (options.frame_id != kMavFrameLocalFrd && options.frame_id != kMavFrameLocalNed) {
    return Status::Error("mavlink: frame_id must be MAV_FRAME_LOCAL_FRD (20) or LOCAL_NED (1)");
  }
  if (!options.T_body_cam.linear().isUnitary(1e-6) || options.T_body_cam.linear().determinant() < 0 ||
      !options.T_local_world.linear().isUnitary(1e-6) || options.T_local_world.linear().determinant() < 0) {
    return Status::Error(
        "mavlink: T_body_cam and T_local_world need rotation matrices (orthonormal, det +1)");
  }
  PLUMB_RETURN_IF_ERROR(transport_.open(endpoint));
  options_ = options;
  frames_.T_body_cam = options.T_body_cam;
  frames_.T_local_world = options.use_T_local_world ? options.T_local_world : options.T_body_cam;
  stats_ = MavlinkStats();
  sequence_ = 0;
  reset_counter_ = 0;
  last_had_pose_ = false;
  has_previous_ = false;
  next_heartbeat_ns_ = std::numeric_limits<int64_t>::min();  // first publish sends one
  return Status::Ok();
}

bool MavlinkOdometrySink::sendMessage(uint32_t message_id, uint8_t crc_extra, const uint8_t* payload,
                                      std::size_t payload_size) {
  MavlinkFrameHeader header;
  header.sequence = sequence_++;  // dropped frames still use a number: receivers see the loss
  header.system_id = options_.system_id;
  header.component_id = options_.component_id;
  header.message_id = message_id;
  const std::size_t size = writeMavlinkV2Frame(header, crc_extra, payload, payload_size, frame_);
  if (!transport_.trySend(frame_, size)) {
    ++stats_.dropped;
    return false;
  }
  stats_.bytes_sent += size;
  return true;
}

void MavlinkOdometrySink::sendHeartbeatIfDue(int64_t now_ns) {
  if (!isOpen() || options_.heartbeat_period_s <= 0.0 || now_ns < next_heartbeat_ns_) return;
  const auto period_ns = static_cast<int64_t>(options_.heartbeat_period_s * 1e9);
  // Catch up without a burst after a long pause.
  next_heartbeat_ns_ = next_heartbeat_ns_ == std::numeric_limits<int64_t>::min()
                           ? now_ns + period_ns
                           : std::max(next_heartbeat_ns_ + period_ns, now_ns);
  MavlinkHeartbeat heartbeat;
  heartbeat.system_status = last_had_pose_ ? kMavStateActive : kMavStateCritical;
  packHeartbeatPayload(heartbeat, payload_);
  if (sendMessage(kMavlinkMsgIdHeartbeat, kMavlinkCrcExtraHeartbeat, payload_,
                  kMavlinkHeartbeatPayloadBytes)) {
    ++stats_.heartbeats_sent;
  }
}

void MavlinkOdometrySink::buildOdometry(const OdometrySample& sample, MavlinkOdometry* out) {
  MavlinkOdometry& m = *out;
  if (sample.reset) {
    ++reset_counter_;
    ++stats_.resets;
    has_previous_ = false;  // no velocity across a jump
  }
  const Eigen::Isometry3d T_local_body = localBodyPose(sample.T_world_cam, frames_);
  const Eigen::Vector3d p = T_local_body.translation();
  const Eigen::Quaterniond q(T_local_body.linear());

  m.time_usec = sample.timestamp_s > 0.0 ? static_cast<uint64_t>(std::llround(sample.timestamp_s * 1e6)) : 0u;
  m.x = static_cast<float>(p.x());
  m.y = static_cast<float>(p.y());
  m.z = static_cast<float>(p.z());
  m.q[0] = static_cast<float>(q.w());
  m.q[1] = static_cast<float>(q.x());
  m.q[2] = static_cast<float>(q.y());
  m.q[3] = static_cast<float>(q.z());

  // Linear and angular velocity of the body, in the body frame (child_frame_id BODY_FRD), from
  // the previous frame: as the current map places it when the sample says (no map update in the
  // velocity), else the previous published pose. Unknown (NaN) on the first pose and after a
  // reset or a gap.
  const double dt = sample.timestamp_s - previous_time_s_;
  const bool have_velocity = has_previous_ && dt > 1e-6;
  const bool previous_in_map = sample.has_previous_in_map && sample.previous_timestamp_s == previous_time_s_;
  const Eigen::Isometry3d& T_world_previous_cam = previous_in_map ? sample.T_world_previous_cam : previous_T_world_cam_;
  if (have_velocity) {
    const Eigen::Isometry3d T_local_previous_body = localBodyPose(T_world_previous_cam, frames_);
    const Eigen::Matrix3d& R = T_local_body.linear();
    const Eigen::Vector3d v_body = R.transpose() * (p - T_local_previous_body.translation()) / dt;
    const Eigen::Vector3d w_body = logSO3(T_local_previous_body.linear().transpose() * R) / dt;
    m.vx = static_cast<float>(v_body.x());
    m.vy = static_cast<float>(v_body.y());
    m.vz = static_cast<float>(v_body.z());
    m.rollspeed = static_cast<float>(w_body.x());
    m.pitchspeed = static_cast<float>(w_body.y());
    m.yawspeed = static_cast<float>(w_body.z());
  } else {
    m.vx = m.vy = m.vz = kNaN;
    m.rollspeed = m.pitchspeed = m.yawspeed = kNaN;
  }
  previous_time_s_ = sample.timestamp_s;
  has_previous_ = true;

  std::fill(std::begin(m.pose_covariance), std::end(m.pose_covariance), 0.f);
  m.pose_covariance[0] = kNaN;
  if (sample.has_covariance) {
    const Matrix6d covariance = mavlinkPoseCovariance(sample.covariance, sample.T_world_cam, frames_);
    if (covariance.allFinite()) upperTriangle21(covariance, m.pose_covariance);
  }
  // Velocity covariance from the two poses' covariances relative to the map (odometry_frames.h).
  std::fill(std::begin(m.velocity_covariance), std::end(m.velocity_covariance), 0.f);
  m.velocity_covariance[0] = kNaN;
  if (have_velocity && previous_has_local_covariance_ && sample.has_local_covariance) {
    const Matrix6d covariance =
        mavlinkVelocityCovariance(previous_local_covariance_, sample.local_covariance, T_world_previous_cam,
                                  sample.T_world_cam, dt, frames_);
    if (covariance.allFinite()) upperTriangle21(covariance, m.velocity_covariance);
  }
  previous_T_world_cam_ = sample.T_world_cam;
  previous_has_local_covariance_ = sample.has_local_covariance;
  previous_local_covariance_ = sample.local_covariance;

  m.frame_id = options_.frame_id;
  m.child_frame_id = kMavFrameBodyFrd;
  m.reset_counter = reset_counter_;
  m.estimator_type = options_.estimator_type;
  m.quality = static_cast<int8_t>(std::clamp(sample.tracking_quality, 0, 100));
}

void MavlinkOdometrySink::publish(const OdometrySample& sample) { publish(sample, monotonicNowNs()); }

void MavlinkOdometrySink::publish(const OdometrySample& sample, int64_t now_ns) {
  if (!isOpen()) return;
  last_had_pose_ = sample.has_pose;
  sendHeartbeatIfDue(now_ns);
  if (!sample.has_pose) {
    ++stats_.skipped_no_pose;
    if (sample.reset) {  // a reset while lost still counts, for the next pose
      ++reset_counter_;
      ++stats_.resets;
    }
    has_previous_ = false;
    return;
  }
  buildOdometry(sample, &last_odometry_);
  if (options_.hold_until_velocity_known && std::isnan(last_odometry_.vx)) {
    ++stats_.skipped_unknown_velocity;
    return;
  }
  packOdometryPayload(last_odometry_, payload_);
  if (sendMessage(kMavlinkMsgIdOdometry, kMavlinkCrcExtraOdometry, payload_, kMavlinkOdometryPayloadBytes)) {
    ++stats_.odometry_sent;
  }
}

}  // namespace plumb
