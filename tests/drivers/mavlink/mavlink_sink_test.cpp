// MavlinkOdometrySink end to end over real sockets and a pseudo-terminal: what arrives decodes to
// the frame-changed pose, nothing blocks when nobody reads, and publish() allocates nothing.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "drivers/mavlink/mavlink_endpoint.h"
#include "drivers/mavlink/mavlink_odometry_sink.h"
#include "mavlink_test_decoder.h"
#include "platform/allocation_counter.h"
#include "solver/se3.h"

namespace plumb {
namespace {

using namespace mavtest;

constexpr int64_t kSecond = 1000000000;

// A UDP socket on 127.0.0.1 with a kernel-chosen port.
struct UdpReceiver {
  int fd = -1;
  uint16_t port = 0;
  UdpReceiver() {
    fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
    socklen_t len = sizeof(a);
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
  }
  ~UdpReceiver() { close(); }
  void close() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  std::vector<std::vector<uint8_t>> drain() {
    std::vector<std::vector<uint8_t>> out;
    uint8_t buf[512];
    for (;;) {
      const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
      if (n <= 0) break;
      out.emplace_back(buf, buf + n);
    }
    return out;
  }
};

Eigen::Isometry3d cameraPose(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expSO3(Eigen::Vector3d(0.1 * std::sin(t), 0.4 * t, 0.05 * std::cos(t)));
  T.translation() = Eigen::Vector3d(0.5 * std::sin(t), 0.1 * t, 0.3 * t);
  return T;
}

OdometrySample sampleAt(int k) {
  OdometrySample s;
  s.timestamp_s = 100.0 + k / 30.0;
  s.has_pose = true;
  s.T_world_cam = cameraPose(k / 30.0);
  s.tracking_quality = 80;
  s.has_covariance = true;
  Matrix6d A = Matrix6d::Identity() * 0.01;
  A(0, 3) = 0.002 * (k + 1);
  A(4, 1) = -0.003;
  s.covariance = A * A.transpose();
  return s;
}

MavlinkOptions udpOptions(uint16_t port) {
  MavlinkOptions o;
  o.endpoint = "udp:127.0.0.1:" + std::to_string(port);
  return o;
}

TEST(MavlinkEndpoint, ParsesUdpAndSerial) {
  MavlinkEndpoint e;
  ASSERT_TRUE(parseMavlinkEndpoint("udp:127.0.0.1:14540", &e).ok());
  EXPECT_EQ(e.kind, MavlinkEndpoint::Kind::kUdp);
  EXPECT_EQ(e.host, "127.0.0.1");
  EXPECT_EQ(e.port, 14540);
  ASSERT_TRUE(parseMavlinkEndpoint("serial:/dev/ttyUSB0:921600", &e).ok());
  EXPECT_EQ(e.kind, MavlinkEndpoint::Kind::kSerial);
  EXPECT_EQ(e.device, "/dev/ttyUSB0");
  EXPECT_EQ(e.baud, 921600);
}

TEST(MavlinkEndpoint, RejectsBadSpecsWithClearMessages) {
  MavlinkEndpoint e;
  const struct {
    const char* spec;
    const char* message_part;
  } cases[] = {{"", "no transport prefix"},
               {"tcp:1.2.3.4:5760", "unknown transport 'tcp'"},
               {"udp:127.0.0.1", "missing :PORT"},
               {"udp::14540", "empty host"},
               {"udp:127.0.0.1:0", "port must be a number in 1..65535"},
               {"udp:127.0.0.1:70000", "1..65535"},
               {"udp:127.0.0.1:14x", "port must be a number"},
               {"udp:::1:14540", "IPv6"},
               {"serial:/dev/ttyUSB0", "missing :BAUD"},
               {"serial::921600", "empty device path"},
               {"serial:/dev/ttyUSB0:12345", "unsupported baud rate '12345'"}};
  for (const auto& c : cases) {
    const Status st = parseMavlinkEndpoint(c.spec, &e);
    ASSERT_FALSE(st.ok()) << c.spec;
    EXPECT_NE(st.message().find(c.message_part), std::string::npos) << st.message();
    EXPECT_NE(st.message().find(std::string("'") + c.spec + "'"), std::string::npos) << st.message();
  }
}

TEST(MavlinkSink, OpenReportsUnusableEndpoints) {
  MavlinkOdometrySink sink;
  MavlinkOptions o;
  o.endpoint = "udp:no-such-host.invalid:14540";
  EXPECT_FALSE(sink.open(o).ok());
  o.endpoint = "serial:/nonexistent/ttyX:57600";
  Status st = sink.open(o);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("/nonexistent/ttyX"), std::string::npos) << st.message();
  o.endpoint = "serial:/dev/null:57600";
  st = sink.open(o);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("not a serial port"), std::string::npos) << st.message();
  EXPECT_FALSE(sink.isOpen());
}

TEST(MavlinkSink, RejectsExtrinsicsThatAreNotRotations) {
  UdpReceiver rx;
  MavlinkOdometrySink sink;
  MavlinkOptions o = udpOptions(rx.port);
  o.T_body_cam.linear() = -o.T_body_cam.linear();  // a reflection: det -1
  const Status st = sink.open(o);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("T_body_cam"), std::string::npos);
}

TEST(MavlinkSink, ExplicitLocalFrameIsUsed) {
  UdpReceiver rx;
  MavlinkOdometrySink sink;
  MavlinkOptions o = udpOptions(rx.port);
  o.use_T_local_world = true;
  o.T_local_world = forwardCameraBodyFrdExtrinsic();
  o.T_local_world.translation() = Eigen::Vector3d(10, 20, -5);  // start at (10, 20, -5)
  ASSERT_TRUE(sink.open(o).ok());
  MavlinkOdometry m;
  sink.buildOdometry(sampleAt(0), &m);
  MavlinkFrameChange frames;
  frames.T_local_world = o.T_local_world;
  const Eigen::Vector3d p = localBodyPose(sampleAt(0).T_world_cam, frames).translation();
  EXPECT_NEAR(m.x, p.x(), 1e-5);
  EXPECT_NEAR(m.y, p.y(), 1e-5);
  EXPECT_NEAR(m.z, p.z(), 1e-5);
  EXPECT_NEAR(m.x, 10.0, 0.01);
}

// The velocity covariance: from the two poses' map-relative covariances (odometry_frames.h) when
// both samples carry one, unknown (NaN) otherwise.
TEST(MavlinkSink, VelocityCovarianceFromConsecutiveLocalCovariances) {
  UdpReceiver rx;
  MavlinkOdometrySink sink;
  ASSERT_TRUE(sink.open(udpOptions(rx.port)).ok());
  const MavlinkFrameChange frames;
  MavlinkOdometry m;
  OdometrySample s0 = sampleAt(0), s1 = sampleAt(1), s2 = sampleAt(2);
  Matrix6d L = Matrix6d::Identity() * 1e-6;
  L(0, 3) = L(3, 0) = 2e-7;
  for (OdometrySample* s : {&s0, &s1}) {
    s->has_local_covariance = true;
    s->local_covariance = L;
  }
  sink.buildOdometry(s0, &m);
  EXPECT_TRUE(std::isnan(m.velocity_covariance[0]));  // no velocity yet
  sink.buildOdometry(s1, &m);
  const Matrix6d expected =
      mavlinkVelocityCovariance(L, L, s0.T_world_cam, s1.T_world_cam, s1.timestamp_s - s0.timestamp_s, frames);
  int i = 0;
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c, ++i)
      EXPECT_NEAR(m.velocity_covariance[i], expected(r, c), 1e-6 * expected.cwiseAbs().maxCoeff()) << r << " " << c;
  EXPECT_GT(m.velocity_covariance[0], 0.f);
  sink.buildOdometry(s2, &m);  // s2 has no local covariance
  EXPECT_TRUE(std::isnan(m.velocity_covariance[0]));
}

// Local BA or a loop moves the map between two frames: the second pose is published in the moved
// map, the first was not. The velocity is the motion from the previous frame as the moved map
// places it (OdometrySample::T_world_previous_cam), so the map's move is not sent as velocity;
// a sample without it, or naming another frame, gives the published poses' difference.
TEST(MavlinkSink, AMapUpdateBetweenTwoFramesIsNotSentAsVelocity) {
  UdpReceiver rx;
  MavlinkOdometrySink sink;
  ASSERT_TRUE(sink.open(udpOptions(rx.port)).ok());
  auto velocity = [](const MavlinkOdometry& m) {
    return Vector6d((Vector6d() << m.vx, m.vy, m.vz, m.rollspeed, m.pitchspeed, m.yawspeed).finished());
  };
  const OdometrySample s0 = sampleAt(0), s1 = sampleAt(1);
  MavlinkOdometry m;
  sink.buildOdometry(s0, &m);
  sink.buildOdometry(s1, &m);
  const Vector6d no_update = velocity(m);  // the true motion: no map change between the frames
  ASSERT_TRUE(no_update.allFinite());

  // 27 mm and 0.5 deg: what one keyframe's BA moved synth:office_loop's next pose by.
  const Eigen::Isometry3d C = Eigen::Translation3d(0.02, -0.015, 0.01) *
                              Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d(0.3, 1, 0.2).normalized());
  OdometrySample moved = s1;
  moved.T_world_cam = C * s1.T_world_cam;
  for (int variant = 0; variant < 3; ++variant) {
    MavlinkOdometrySink fresh;
    ASSERT_TRUE(fresh.open(udpOptions(rx.port)).ok());
    OdometrySample s = moved;
    s.has_previous_in_map = variant != 1;
    s.previous_timestamp_s = variant == 2 ? s0.timestamp_s - 1.0 / 30 : s0.timestamp_s;  // 2: another frame
    s.T_world_previous_cam = C * s0.T_world_cam;
    fresh.buildOdometry(s0, &m);
    fresh.buildOdometry(s, &m);
    const Vector6d v = velocity(m);
    if (variant == 0) {
      EXPECT_LT((v - no_update).norm(), 1e-4 * no_update.norm()) << v.transpose() << " vs " << no_update.transpose();
    } else {
      // The published difference carries the map's move: ~1 m/s over one frame at 30 Hz.
      EXPECT_GT((v.head<3>() - no_update.head<3>()).norm(), 0.5) << "variant " << variant;
    }
  }
}

TEST(MavlinkSink, UdpRoundTripDecodesToFrameChangedPose) {
  UdpReceiver rx;
  MavlinkOdometrySink sink;
  MavlinkOptions options = udpOptions(rx.port);
  options.hold_until_velocity_known = false;  // see the first pose's NaN velocity too
  ASSERT_TRUE(sink.open(options).ok());
  const MavlinkFrameChange frames;  // the defaults the sink uses
  constexpr int kFrames = 5;
  for (int k = 0; k < kFrames; ++k) {
    OdometrySample s = sampleAt(k);
    s.has_covariance = k != 2;  // one frame without covariance
    sink.publish(s, k * kSecond / 30);
  }
  const auto datagrams = rx.drain();
  ASSERT_EQ(datagrams.size(), 1u + kFrames);  // one heartbeat (period 1 s) + the odometry

  DecodedFrame hb;
  ASSERT_TRUE(decodeFrame(datagrams[0].data(), datagrams[0].size(), 50, &hb));
  EXPECT_TRUE(hb.crc_ok);
  EXPECT_EQ(hb.msgid, 0u);
  EXPECT_EQ(hb.compid, 197);
  EXPECT_EQ(hb.payload[4], 18);  // MAV_TYPE_ONBOARD_CONTROLLER

  const auto def = odometryDefinition();
  auto at = [&](const char* name) { return fieldOffset(def, name); };
  for (int k = 0; k < kFrames; ++k) {
    const auto& d = datagrams[1 + k];
    DecodedFrame f;
    ASSERT_TRUE(decodeFrame(d.data(), d.size(), 91, &f));
    ASSERT_EQ(f.frame_size, d.size());
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 331u);
    EXPECT_EQ(f.sysid, 1);
    EXPECT_EQ(f.compid, 197);
    EXPECT_EQ(f.seq, 1 + k);
    EXPECT_EQ(f.length, 233);  // quality 80 is the last byte: nothing to truncate
    const OdometrySample s = sampleAt(k);
    const Eigen::Isometry3d T_lb = localBodyPose(s.T_world_cam, frames);
    EXPECT_EQ(readU64(f.payload, at("time_usec")), static_cast<uint64_t>(std::llround(s.timestamp_s * 1e6)));
    EXPECT_NEAR(readFloat(f.payload, at("x")), T_lb.translation().x(), 1e-6);
    EXPECT_NEAR(readFloat(f.payload, at("y")), T_lb.translation().y(), 1e-6);
    EXPECT_NEAR(readFloat(f.payload, at("z")), T_lb.translation().z(), 1e-6);
    Eigen::Quaterniond q(T_lb.linear());
    const double sign = readFloat(f.payload, at("q")) * q.w() < 0 ? -1.0 : 1.0;
    EXPECT_NEAR(readFloat(f.payload, at("q") + 0), sign * q.w(), 1e-6);
    EXPECT_NEAR(readFloat(f.payload, at("q") + 4), sign * q.x(), 1e-6);
    EXPECT_NEAR(readFloat(f.payload, at("q") + 8), sign * q.y(), 1e-6);
    EXPECT_NEAR(readFloat(f.payload, at("q") + 12), sign * q.z(), 1e-6);
    if (k == 0) {
      EXPECT_TRUE(std::isnan(readFloat(f.payload, at("vx"))));  // no previous pose yet
      EXPECT_TRUE(std::isnan(readFloat(f.payload, at("yawspeed"))));
    } else {
      // Velocity in the body frame from the previous pose (finite difference, body axes).
      const Eigen::Isometry3d T_prev = localBodyPose(sampleAt(k - 1).T_world_cam, frames);
      const double dt = 1.0 / 30.0;
      const Eigen::Vector3d v = T_lb.linear().transpose() * (T_lb.translation() - T_prev.translation()) / dt;
      const Eigen::Vector3d w = logSO3(T_prev.linear().transpose() * T_lb.linear()) / dt;
      EXPECT_NEAR(readFloat(f.payload, at("vx")), v.x(), 1e-4);
      EXPECT_NEAR(readFloat(f.payload, at("vy")), v.y(), 1e-4);
      EXPECT_NEAR(readFloat(f.payload, at("vz")), v.z(), 1e-4);
      EXPECT_NEAR(readFloat(f.payload, at("rollspeed")), w.x(), 1e-4);
      EXPECT_NEAR(readFloat(f.payload, at("pitchspeed")), w.y(), 1e-4);
      EXPECT_NEAR(readFloat(f.payload, at("yawspeed")), w.z(), 1e-4);
      // Forward motion of the camera (world z grows 0.3 m/s) shows as positive body vx.
      EXPECT_GT(readFloat(f.payload, at("vx")), 0.1f);
    }
    if (k == 2) {
      EXPECT_TRUE(std::isnan(readFloat(f.payload, at("pose_covariance"))));
    } else {
      const Matrix6d cov = mavlinkPoseCovariance(s.covariance, s.T_world_cam, frames);
      int i = 0;
      for (int r = 0; r < 6; ++r)
        for (int c = r; c < 6; ++c, ++i)
          EXPECT_NEAR(readFloat(f.payload, at("pose_covariance") + 4 * i), cov(r, c),
                      1e-6 * cov.cwiseAbs().maxCoeff());
    }
    EXPECT_TRUE(std::isnan(readFloat(f.payload, at("velocity_covariance"))));
    EXPECT_EQ(f.payload[at("frame_id")], 20);
    EXPECT_EQ(f.payload[at("child_frame_id")], 12);
    EXPECT_EQ(f.payload[at("reset_counter")], 0);
    EXPECT_EQ(f.payload[at("estimator_type")], 2);
    EXPECT_EQ(static_cast<int8_t>(f.payload[at("quality")]), 80);
  }
  EXPECT_EQ(sink.stats().odometry_sent, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(sink.stats().heartbeats_sent, 1u);
  EXPECT_EQ(sink.stats().dropped, 0u);
  uint64_t bytes = 0;
  for (const auto& d : datagrams) bytes += d.size();
  EXPECT_EQ(sink.stats().bytes_sent, bytes);
}

TEST(MavlinkSink, HeartbeatAtOneHertzResetCounterAndLostFrames) {
  UdpReceiver rx;
  MavlinkOdometrySink sink;
  ASSERT_TRUE(sink.open(udpOptions(rx.port)).ok());
  // 3.5 s of frames at 30 Hz; frames 40..44 lost; a reset (new segment) at 45 and 70.
  for (int k = 0; k < 105; ++k) {
    OdometrySample s = sampleAt(k);
    s.has_pose = !(k >= 40 && k < 45);
    s.reset = (k == 45 || k == 70);
    s.tracking_quality = 0;  // unknown: quality byte 0 -> truncated away on the wire
    sink.publish(s, k * kSecond / 30);
  }
  int heartbeats = 0, odometry = 0, last_reset = -1;
  for (const auto& d : rx.drain()) {
    DecodedFrame f;
    ASSERT_TRUE(decodeFrame(d.data(), d.size(), d[7] == 0 && d[8] == 0 ? 50 : 91, &f));
    ASSERT_TRUE(f.crc_ok);
    if (f.msgid == 0) {
      ++heartbeats;
      continue;
    }
    EXPECT_EQ(f.length, 232);                            // trailing quality 0 truncated
    EXPECT_FALSE(std::isnan(readFloat(f.payload, 36)));  // vx always known (held otherwise)
    const int reset = f.payload[230];
    EXPECT_GE(reset, last_reset);
    last_reset = reset;
    ++odometry;
  }
  EXPECT_EQ(heartbeats, 4);  // t = 0, 1, 2, 3 s
  // 105 frames - 5 lost - 3 held (no velocity yet: frame 0, 45 after the gap + reset, 70 reset).
  EXPECT_EQ(odometry, 97);
  EXPECT_EQ(last_reset, 2);
  EXPECT_EQ(sink.stats().skipped_no_pose, 5u);
  EXPECT_EQ(sink.stats().skipped_unknown_velocity, 3u);
  EXPECT_EQ(sink.stats().resets, 2u);
}

TEST(MavlinkSink, AbsentOrStalledReceiverNeverBlocks) {
  // Absent: a port nobody listens on. Stalled: a socket with a tiny buffer that is never read.
  uint16_t absent_port;
  {
    UdpReceiver gone;
    absent_port = gone.port;
  }
  UdpReceiver stalled;
  const int tiny = 1;
  ::setsockopt(stalled.fd, SOL_SOCKET, SO_RCVBUF, &tiny, sizeof(tiny));
  for (uint16_t port : {absent_port, stalled.port}) {
    MavlinkOdometrySink sink;
    ASSERT_TRUE(sink.open(udpOptions(port)).ok());
    constexpr int kMessages = 20000;
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < kMessages; ++k) sink.publish(sampleAt(k), k * kSecond / 30);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 5.0);  // ~20k sendto calls; a blocking send would hang here
    const MavlinkStats& st = sink.stats();
    EXPECT_EQ(st.skipped_unknown_velocity, 1u);  // the first pose
    EXPECT_EQ(st.odometry_sent + st.heartbeats_sent + st.dropped + st.skipped_unknown_velocity,
              static_cast<uint64_t>(kMessages) + (kMessages / 30 + 1))
        << "every message is either handed to the kernel or counted as dropped";
  }
}

TEST(MavlinkSink, PublishAllocatesNothing) {
  UdpReceiver rx;
  MavlinkOdometrySink sink;
  ASSERT_TRUE(sink.open(udpOptions(rx.port)).ok());
  sink.publish(sampleAt(0), 0);  // warm-up
  AllocationScope scope;
  for (int k = 1; k < 200; ++k) {
    OdometrySample s = sampleAt(k);
    s.reset = (k == 100);
    s.has_pose = (k != 150);
    sink.publish(s, k * kSecond / 30);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(sink.stats().heartbeats_sent, 7u);  // t = 0 .. 6 s
}

// Opens a pseudo-terminal pair; returns the master fd and the slave path.
int openPty(std::string* slave_path) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) return -1;
  char name[128];
  if (::ptsname_r(master, name, sizeof(name)) != 0) return -1;
  *slave_path = name;
  return master;
}

std::vector<uint8_t> readAllFromFd(int fd) {
  std::vector<uint8_t> bytes;
  uint8_t buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof(buf));
    if (n <= 0) break;
    bytes.insert(bytes.end(), buf, buf + n);
  }
  return bytes;
}

TEST(MavlinkSink, SerialDropsWhenFullAndKeepsTheStreamFrameAligned) {
  std::string slave;
  const int master = openPty(&slave);
  if (master < 0) GTEST_SKIP() << "no pseudo-terminals here";
  MavlinkOptions o;
  o.endpoint = "serial:" + slave + ":921600";
  MavlinkOdometrySink sink;
  ASSERT_TRUE(sink.open(o).ok()) << sink.open(o).message();

  // Nobody reads the master: the pty buffer fills, then frames are dropped, never waited for.
  const auto start = std::chrono::steady_clock::now();
  AllocationScope scope;
  constexpr int kMessages = 2000;
  for (int k = 0; k < kMessages; ++k) sink.publish(sampleAt(k), k * kSecond / 30);
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  const MavlinkStats full = sink.stats();
  EXPECT_GT(full.dropped, 0u);
  EXPECT_GT(full.odometry_sent, 0u);

  // Drain, send once more (flushes any torn tail first), drain again: whole frames only.
  std::vector<uint8_t> stream = readAllFromFd(master);
  sink.publish(sampleAt(kMessages), kMessages * kSecond / 30);
  const std::vector<uint8_t> rest = readAllFromFd(master);
  stream.insert(stream.end(), rest.begin(), rest.end());
  std::size_t pos = 0;
  uint64_t odometry = 0, heartbeats = 0;
  while (pos < stream.size()) {
    DecodedFrame f;
    const uint8_t* p = stream.data() + pos;
    ASSERT_TRUE(decodeFrame(p, stream.size() - pos, p[7] == 0 ? 50 : 91, &f)) << "at " << pos;
    ASSERT_TRUE(f.crc_ok) << "torn or corrupt frame at byte " << pos;
    (f.msgid == 331 ? odometry : heartbeats)++;
    pos += f.frame_size;
  }
  EXPECT_EQ(odometry + heartbeats, sink.stats().odometry_sent + sink.stats().heartbeats_sent);
  EXPECT_EQ(sink.stats().bytes_sent, stream.size());
  ::close(master);
}

}  // namespace
}  // namespace plumb
