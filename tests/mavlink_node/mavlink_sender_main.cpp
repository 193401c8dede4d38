// plumb_mavlink_sender: sends the ODOMETRY stream of a known synthetic camera trajectory through
// MavlinkOdometrySink, and writes what it sent to a text file so an independent decoder
// (decode_check.js, npm node-mavlink) can compare. Also a small demo to point at an autopilot,
// a ground station or mavlink-router:
//
//   plumb_mavlink_sender --endpoint udp:127.0.0.1:14550 --frames 3000 --rate-hz 30
//
// The trajectory (camera world: x right, y down, z forward): a forward drift with a side-to-side
// weave and gentle yaw/pitch/roll; frames 150..154 are "lost" (no pose, nothing sent); at frames
// 100 and 200 the pose jumps by 0.5 m (a new map segment: reset flag); every 10th frame has no
// covariance.
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "drivers/mavlink/mavlink_odometry_sink.h"
#include "platform/monotonic_time.h"
#include "solver/se3.h"

namespace {

using plumb::Matrix6d;

Eigen::Isometry3d syntheticCameraPose(int k) {
  const double t = k / 30.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = plumb::expSO3(
      Eigen::Vector3d(0.15 * std::sin(0.7 * t), 0.5 * std::sin(0.3 * t), 0.1 * std::sin(0.9 * t)));
  T.translation() = Eigen::Vector3d(0.8 * std::sin(0.5 * t), 0.2 * std::sin(t), 0.4 * t);
  const int jumps = (k >= 100) + (k >= 200);
  T.translation().x() += 0.5 * jumps;
  return T;
}

Matrix6d syntheticCovariance(int k) {
  Matrix6d A = Matrix6d::Zero();
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c <= r; ++c) A(r, c) = 0.002 * std::cos(0.1 * k + r + 2.0 * c);
    A(r, r) = 0.01 + 0.001 * r;
  }
  return A * A.transpose();
}

int usage(const char* argv0) {
  std::fprintf(stderr,
               "usage: %s --endpoint udp:HOST:PORT|serial:DEVICE:BAUD [--frames N (250)]\n"
               "          [--rate-hz R (30; 0 = as fast as possible)] [--expected FILE]\n",
               argv0);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string endpoint, expected_path;
  int frames = 250;
  double rate_hz = 30.0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc) return usage(argv[0]);
    if (arg == "--endpoint")
      endpoint = argv[++i];
    else if (arg == "--frames")
      frames = std::atoi(argv[++i]);
    else if (arg == "--rate-hz")
      rate_hz = std::atof(argv[++i]);
    else if (arg == "--expected")
      expected_path = argv[++i];
    else
      return usage(argv[0]);
  }
  if (endpoint.empty() || frames <= 0) return usage(argv[0]);

  plumb::MavlinkOptions options;
  options.endpoint = endpoint;
  plumb::MavlinkOdometrySink sink;
  const plumb::Status st = sink.open(options);
  if (!st.ok()) {
    std::fprintf(stderr, "plumb_mavlink_sender: %s\n", st.message().c_str());
    return 1;
  }
  std::FILE* expected = nullptr;
  if (!expected_path.empty()) {
    expected = std::fopen(expected_path.c_str(), "w");
    if (!expected) {
      std::fprintf(stderr, "plumb_mavlink_sender: cannot write '%s'\n", expected_path.c_str());
      return 1;
    }
    std::fprintf(expected,
                 "# k T_world_cam:tx ty tz qw qx qy qz | sent: time_usec x y z qw qx qy qz vx vy vz"
                 " rollspeed pitchspeed yawspeed reset_counter quality pose_covariance[21]\n");
  }

  const int64_t start_ns = plumb::monotonicNowNs();
  for (int k = 0; k < frames; ++k) {
    if (rate_hz > 0) {
      plumb::sleepUntilMonotonicNs(start_ns + static_cast<int64_t>(k * 1e9 / rate_hz));
    }
    plumb::OdometrySample sample;
    sample.timestamp_s = 1000.0 + k / 30.0;
    sample.has_pose = !(k >= 150 && k < 155);
    sample.T_world_cam = syntheticCameraPose(k);
    sample.tracking_quality = 40 + (k % 61);
    sample.has_covariance = (k % 10) != 9;
    sample.covariance = syntheticCovariance(k);
    sample.reset = (k == 100 || k == 200);
    const uint64_t sent_before = sink.stats().odometry_sent;
    sink.publish(sample);
    if (!expected || sink.stats().odometry_sent == sent_before) continue;
    const plumb::MavlinkOdometry& m = sink.lastOdometry();
    const Eigen::Quaterniond q(sample.T_world_cam.linear());
    const Eigen::Vector3d& t = sample.T_world_cam.translation();
    std::fprintf(expected, "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g", k, t.x(), t.y(), t.z(), q.w(),
                 q.x(), q.y(), q.z());
    std::fprintf(expected, " %" PRIu64, m.time_usec);
    const float values[] = {m.x,  m.y,  m.z,  m.q[0],      m.q[1],       m.q[2],    m.q[3],
                            m.vx, m.vy, m.vz, m.rollspeed, m.pitchspeed, m.yawspeed};
    for (float v : values) std::fprintf(expected, " %.9g", v);
    std::fprintf(expected, " %d %d", m.reset_counter, m.quality);
    for (float v : m.pose_covariance) std::fprintf(expected, " %.9g", v);
    std::fprintf(expected, "\n");
  }
  if (expected) std::fclose(expected);
  const plumb::MavlinkStats& s = sink.stats();
  std::printf("plumb_mavlink_sender: %" PRIu64 " odometry, %" PRIu64 " heartbeats, %" PRIu64
              " dropped, %" PRIu64 " bytes, %" PRIu64 " frames without pose, %" PRIu64 " resets\n",
              s.odometry_sent, s.heartbeats_sent, s.dropped, s.bytes_sent, s.skipped_no_pose, s.resets);
  return 0;
}
