// V4L2 capture through the device seam with a fake driver: the exact ioctl sequence, errors
// naming device and ioctl, pairing colour with depth by timestamp, and a device that disappears
// mid-stream and comes back (also under the ResilientSource supervisor).
#include <gtest/gtest.h>

#include "drivers/fault/resilient_source.h"
#include "drivers/v4l2/v4l2_source.h"
#include "tests/drivers/v4l2/fake_v4l2_device.h"

namespace plumb {
namespace {

using test::FakeV4l2Device;
using test::FakeV4l2Node;

PinholeCamera camera4x2() {
  PinholeCamera c;
  c.fx = c.fy = 2;
  c.cx = 2;
  c.cy = 1;
  c.width = 4;
  c.height = 2;
  return c;
}

// Colour node: YUYV 4x2 where Y of every pixel is 16 + k (frame number), U = V = 128 (grey).
FakeV4l2Node colourNode() {
  FakeV4l2Node n;
  n.fill = [](uint64_t k, uint8_t* data, std::size_t, uint32_t*) {
    for (int i = 0; i < 16; i += 2) {
      data[i] = static_cast<uint8_t>(16 + k);
      data[i + 1] = 128;
    }
  };
  return n;
}

// Depth node: Z16 4x2, every pixel = 1000 + k, timestamps offset by `offset_ns` from colour.
FakeV4l2Node depthNode(int64_t offset_ns) {
  FakeV4l2Node n;
  n.fourcc = V4L2_PIX_FMT_Z16;
  n.first_timestamp_ns += offset_ns;
  n.fill = [](uint64_t k, uint8_t* data, std::size_t, uint32_t*) {
    const uint16_t v = static_cast<uint16_t>(1000 + k);
    for (int i = 0; i < 16; i += 2) {
      data[i] = v & 0xFF;
      data[i + 1] = v >> 8;
    }
  };
  return n;
}

uint8_t expectedGrey(uint64_t k) {  // (Y - 16) * 298 / 256, rounded as the converter does
  return static_cast<uint8_t>(std::min<int>(255, (298 * static_cast<int>(k) + 128) >> 8));
}

TEST(V4l2Capture, IssuesTheDocumentedIoctlSequence) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  V4l2SourceOptions options;
  options.buffer_count = 2;
  {
    std::unique_ptr<V4l2Source> source;
    const Status st = V4l2Source::open(options, camera4x2(), fake, &source);
    ASSERT_TRUE(st.ok()) << st.message();
    const std::vector<std::string> expected_open = {
        "open /dev/video0", "VIDIOC_QUERYCAP", "VIDIOC_S_FMT",  "VIDIOC_S_PARM",
        "VIDIOC_REQBUFS",   "VIDIOC_QUERYBUF", "mmap",          "VIDIOC_QUERYBUF",
        "mmap",             "VIDIOC_QBUF",     "VIDIOC_QBUF",   "VIDIOC_STREAMON"};
    EXPECT_EQ(fake.log, expected_open);
    fake.log.clear();
    RgbdImage out;
    ASSERT_EQ(source->next(out), SourceResult::kFrame);
    EXPECT_EQ(fake.log, (std::vector<std::string>{"poll", "VIDIOC_DQBUF", "VIDIOC_QBUF"}));
    EXPECT_EQ(out.bgr.at<cv::Vec3b>(1, 3), cv::Vec3b(0, 0, 0));  // frame 0: Y = 16 -> black
    EXPECT_TRUE(cv::countNonZero(out.depth_raw) == 0) << "colour-only: depth is 'no reading'";
    ASSERT_EQ(source->next(out), SourceResult::kFrame);
    EXPECT_EQ(out.bgr.at<cv::Vec3b>(0, 0)[1], expectedGrey(1));
    EXPECT_EQ(out.sequence, 1u);
    EXPECT_EQ(out.t_sensor_ns, 1'000'000'000 + 33'333'000);  // timeval: microseconds
    fake.log.clear();
  }
  EXPECT_EQ(fake.log, (std::vector<std::string>{"VIDIOC_STREAMOFF", "munmap", "munmap", "close"}));
  EXPECT_EQ(fake.live_mappings, 0);
  EXPECT_EQ(fake.open_fds, 0);
}

TEST(V4l2Capture, ErrorsNameTheDeviceAndTheIoctl) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video7"] = colourNode();
  fake.nodes["/dev/video7"].failing_request = VIDIOC_REQBUFS;
  fake.nodes["/dev/video7"].failing_errno = EBUSY;
  V4l2SourceOptions options;
  options.colour_device = "/dev/video7";
  std::unique_ptr<V4l2Source> source;
  Status st = V4l2Source::open(options, camera4x2(), fake, &source);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.message(), "/dev/video7: VIDIOC_REQBUFS failed: Device or resource busy");
  EXPECT_EQ(fake.open_fds, 0) << "a failed open must release the node";

  options.colour_device = "/dev/video9";  // no such node
  st = V4l2Source::open(options, camera4x2(), fake, &source);
  EXPECT_EQ(st.message(), "/dev/video9: open failed: No such file or directory");

  fake.nodes["/dev/video7"].failing_request = 0;
  fake.nodes["/dev/video7"].offered_width = 6;  // the driver substitutes another size
  options.colour_device = "/dev/video7";
  st = V4l2Source::open(options, camera4x2(), fake, &source);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("VIDIOC_S_FMT: asked for yuyv 4x2, driver offers YUYV 6x2"),
            std::string::npos)
      << st.message();
  EXPECT_EQ(fake.live_mappings, 0);
  EXPECT_EQ(fake.open_fds, 0);
}

TEST(V4l2Capture, PairsColourWithDepthByTimestamp) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  // Depth starts two frames late and 4 ms after colour: colour frames 0 and 1 have no partner.
  fake.nodes["/dev/video1"] = depthNode(2 * 33'333'333 + 4'000'000);
  V4l2SourceOptions options;
  options.depth_device = "/dev/video1";
  std::unique_ptr<V4l2Source> source;
  ASSERT_TRUE(V4l2Source::open(options, camera4x2(), fake, &source).ok());
  RgbdImage out;
  for (uint64_t i = 0; i < 3; ++i) {
    ASSERT_EQ(source->next(out), SourceResult::kFrame);
    EXPECT_NEAR(out.depth_timestamp_s - out.timestamp_s, 0.004, 1e-6);
    EXPECT_EQ(out.bgr.at<cv::Vec3b>(0, 0)[0], expectedGrey(i + 2)) << "colour frame " << i + 2;
    EXPECT_EQ(out.depth_raw.at<uint16_t>(1, 3), 1000 + i) << "depth frame " << i;
  }
  EXPECT_EQ(source->pairingStats().unpaired_colour, 2u);
  EXPECT_EQ(source->pairingStats().unpaired_depth, 0u);
  EXPECT_EQ(source->pairingStats().pairs, 3u);
  EXPECT_EQ(source->camera().depth_factor, 1000.0);
}

TEST(V4l2Capture, ADeviceThatDisappearsIsReportedAndCanBeReopened) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video0"].unplug_after_dequeues = 3;
  std::unique_ptr<V4l2Source> source;
  ASSERT_TRUE(V4l2Source::open({}, camera4x2(), fake, &source).ok());
  RgbdImage out;
  for (int i = 0; i < 3; ++i) ASSERT_EQ(source->next(out), SourceResult::kFrame);
  ASSERT_EQ(source->next(out), SourceResult::kError);
  EXPECT_EQ(source->lastError().message(),
            "/dev/video0: VIDIOC_DQBUF failed: No such device (device disconnected)");
  EXPECT_EQ(fake.live_mappings, 0) << "buffers released when the device vanished";
  EXPECT_EQ(fake.open_fds, 0);
  EXPECT_EQ(source->next(out), SourceResult::kError) << "stays failed until reopened";

  const Status still_gone = source->reopen();
  EXPECT_EQ(still_gone.message(), "/dev/video0: open failed: No such device (device disconnected)");
  fake.nodes["/dev/video0"].unplugged = false;  // plugged back in; 10 frames passed meanwhile
  fake.nodes["/dev/video0"].produced += 10;
  ASSERT_TRUE(source->reopen().ok());
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  // The failed DQBUF consumed no frame, so the sensor resumes at frame 3 + 10 = 13; the sequence
  // gap is estimated from the timestamp gap: 2 -> 13.
  EXPECT_EQ(out.sequence, 13u);
}

TEST(V4l2Capture, SupervisorReconnectsAnUnpluggedCameraAndCountsTheLoss) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video0"].unplug_after_dequeues = 5;
  std::unique_ptr<V4l2Source> v4l2;
  ASSERT_TRUE(V4l2Source::open({}, camera4x2(), fake, &v4l2).ok());
  // The fake stays unplugged for two reopen attempts, then is back with 6 frames elapsed.
  class ReplugClock : public VirtualClock {
   public:
    explicit ReplugClock(FakeV4l2Node& node) : node_(node) {}
    void sleepForNs(int64_t ns) override {
      VirtualClock::sleepForNs(ns);
      if (sleeps_ns.size() == 2) {
        node_.unplugged = false;
        node_.produced += 6;
      }
    }
    FakeV4l2Node& node_;
  } clock(fake.nodes["/dev/video0"]);
  ResilientSource supervised(std::move(v4l2), {}, clock);
  RgbdImage out;
  std::vector<uint64_t> sequences;
  for (int i = 0; i < 8; ++i) {
    ASSERT_EQ(supervised.next(out), SourceResult::kFrame);
    sequences.push_back(out.sequence);
  }
  EXPECT_EQ(sequences, (std::vector<uint64_t>{0, 1, 2, 3, 4, 11, 12, 13}));
  EXPECT_EQ(supervised.stats().errors, 1u);
  EXPECT_EQ(supervised.stats().reopen_failures, 2u);
  EXPECT_EQ(supervised.stats().reconnects, 1u);
  EXPECT_EQ(supervised.stats().frames_missing, 6u);
  EXPECT_NE(supervised.stats().last_error.find("/dev/video0"), std::string::npos);
}

}  // namespace
}  // namespace plumb

// Faults a real driver shows (found with vivid's error-injection controls in the virtual-machine
// camera bench, scripts/vm_camera_test.sh), reproduced on the fake.
namespace plumb {
namespace {

TEST(V4l2DriverFaults, BuffersFlaggedErrorAreNeverDeliveredAndCountAsMissing) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video0"].error_frames = {2};  // vivid: "Inject V4L2_BUF_FLAG_ERROR"
  std::unique_ptr<V4l2Source> v4l2;
  ASSERT_TRUE(V4l2Source::open({}, camera4x2(), fake, &v4l2).ok());
  const V4l2Source* capture = v4l2.get();
  VirtualClock clock;
  ResilientSource supervised(std::move(v4l2), {}, clock);
  RgbdImage out;
  std::vector<uint64_t> sequences;
  std::vector<uint8_t> greys;
  while (sequences.size() < 4) {
    const SourceResult r = supervised.next(out);
    ASSERT_NE(r, SourceResult::kError);
    if (r != SourceResult::kFrame) continue;
    sequences.push_back(out.sequence);
    greys.push_back(out.bgr.at<cv::Vec3b>(0, 0)[0]);
  }
  EXPECT_EQ(sequences, (std::vector<uint64_t>{0, 1, 3, 4}));
  EXPECT_EQ(greys[2], expectedGrey(3)) << "the damaged frame 2 must not be delivered";
  EXPECT_EQ(supervised.stats().frames_missing, 1u);
  EXPECT_NE(capture->healthReport().find("error buffers 1"), std::string::npos) << capture->healthReport();
}

TEST(V4l2DriverFaults, TheDriversFrameCounterMayWrap) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video0"].first_sequence = 0xFFFFFFFEu;  // vivid: "Wrap Sequence Number"
  std::unique_ptr<V4l2Source> source;
  ASSERT_TRUE(V4l2Source::open({}, camera4x2(), fake, &source).ok());
  RgbdImage out;
  ASSERT_EQ(source->next(out), SourceResult::kFrame);  // driver 0xFFFFFFFE
  EXPECT_EQ(out.sequence, 0u);
  fake.nodes["/dev/video0"].produced += 2;  // the driver drops 0xFFFFFFFF and 0
  ASSERT_EQ(source->next(out), SourceResult::kFrame);  // driver 1
  EXPECT_EQ(out.sequence, 3u) << "two frames lost across the wrap";
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.sequence, 4u);
}

TEST(V4l2DriverFaults, AStreamingErrorIsReportedAsSuchAndTheNodeRecovers) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video0"].queue_error_after_dequeues = 2;  // vivid: "Inject Fatal Streaming Error"
  std::unique_ptr<V4l2Source> source;
  ASSERT_TRUE(V4l2Source::open({}, camera4x2(), fake, &source).ok());
  RgbdImage out;
  for (int i = 0; i < 2; ++i) ASSERT_EQ(source->next(out), SourceResult::kFrame);
  ASSERT_EQ(source->next(out), SourceResult::kError);
  // Not "poll failed" and not "device disconnected": the driver's own errno for the failed queue.
  EXPECT_EQ(source->lastError().message(), "/dev/video0: VIDIOC_DQBUF failed: Input/output error");
  ASSERT_TRUE(source->reopen().ok());
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
}

TEST(V4l2DriverFaults, FramesLostAcrossAReopenAreCountedAtTheRateTheCameraKept) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video0"].period_ns = 500'000'000;  // 2 Hz, though 30 Hz was asked for
  fake.nodes["/dev/video0"].unplug_after_dequeues = 4;
  std::unique_ptr<V4l2Source> source;
  ASSERT_TRUE(V4l2Source::open({}, camera4x2(), fake, &source).ok());
  RgbdImage out;
  for (int i = 0; i < 4; ++i) ASSERT_EQ(source->next(out), SourceResult::kFrame);
  ASSERT_EQ(source->next(out), SourceResult::kError);
  fake.nodes["/dev/video0"].unplugged = false;
  fake.nodes["/dev/video0"].produced += 3;  // 3 frames (1.5 s) pass while it is away
  ASSERT_TRUE(source->reopen().ok());
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.sequence, 3u + 4u) << "3 frames missing, not the 45 a 30 Hz guess would claim";
}

TEST(V4l2DriverFaults, ACounterJumpFasterThanTheCameraRunsIsNotCountedAsLoss) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  std::unique_ptr<V4l2Source> source;
  ASSERT_TRUE(V4l2Source::open({}, camera4x2(), fake, &source).ok());
  RgbdImage out;
  for (int i = 0; i < 5; ++i) ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.sequence, 4u);
  fake.nodes["/dev/video0"].first_sequence = 100;  // the counter jumps; one frame period passed
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.sequence, 5u) << "not 100 frames lost in 33 ms";
  fake.nodes["/dev/video0"].produced += 2;  // a real drop: 2 frames, 3 periods
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.sequence, 8u);
}

TEST(V4l2DriverFaults, ASlowCameraIsPairedWithinHalfItsFramePeriod) {
  // 2 Hz streams whose depth comes 100 ms after colour (a guest under load, or unsynchronised
  // sensors): half a 30 Hz frame would pair nothing; half of the period they keep pairs them all.
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video0"].period_ns = 500'000'000;
  fake.nodes["/dev/video1"] = depthNode(100'000'000);
  fake.nodes["/dev/video1"].period_ns = 500'000'000;
  V4l2SourceOptions options;
  options.depth_device = "/dev/video1";
  std::unique_ptr<V4l2Source> source;
  ASSERT_TRUE(V4l2Source::open(options, camera4x2(), fake, &source).ok());
  RgbdImage out;
  int frames = 0;
  for (int call = 0; call < 20 && frames < 6; ++call) frames += source->next(out) == SourceResult::kFrame;
  EXPECT_EQ(frames, 6);
  EXPECT_NEAR(out.depth_timestamp_s - out.timestamp_s, 0.1, 1e-6);
  EXPECT_LE(source->pairingStats().unpaired_colour, 1u) << "only before the period is known";
  EXPECT_LE(source->pairingStats().unpaired_depth, 1u);
}

TEST(V4l2DriverFaults, DepthMayComeAsY16) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video1"] = depthNode(1'000'000);
  fake.nodes["/dev/video1"].fourcc = V4L2_PIX_FMT_Y16;  // v4l2loopback has no Z16
  V4l2SourceOptions options;
  options.depth_device = "/dev/video1";
  std::unique_ptr<V4l2Source> source;
  const Status st = V4l2Source::open(options, camera4x2(), fake, &source);
  ASSERT_TRUE(st.ok()) << st.message();
  RgbdImage out;
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.depth_raw.at<uint16_t>(0, 0), 1000);
  EXPECT_NE(source->healthReport().find("depth format y16"), std::string::npos) << source->healthReport();

  fake.nodes["/dev/video1"].refuses_other_formats = true;  // v4l2loopback: EINVAL for Z16
  source.reset();
  fake.log.clear();
  ASSERT_TRUE(V4l2Source::open(options, camera4x2(), fake, &source).ok());
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(fake.count("VIDIOC_S_FMT"), 3) << "colour; depth: Z16 refused, then Y16";

  fake.nodes["/dev/video1"].refuses_other_formats = false;
  fake.nodes["/dev/video1"].fourcc = V4L2_PIX_FMT_GREY;  // 8-bit: never depth
  EXPECT_NE(V4l2Source::open(options, camera4x2(), fake, &source).message().find("asked for z16"),
            std::string::npos);
}

TEST(V4l2DriverFaults, BufferTimestampsAreUsedOnlyWhenOnTheMonotonicClock) {
  FakeV4l2Device fake;
  fake.nodes["/dev/video0"] = colourNode();
  fake.nodes["/dev/video1"] = depthNode(5'000'000);
  // v4l2loopback: CLOCK_MONOTONIC stamps, but the clock flag says "unknown". Pairing must use them.
  fake.nodes["/dev/video0"].timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN;
  fake.nodes["/dev/video1"].timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN;
  V4l2SourceOptions options;
  options.depth_device = "/dev/video1";
  std::unique_ptr<V4l2Source> source;
  ASSERT_TRUE(V4l2Source::open(options, camera4x2(), fake, &source).ok());
  RgbdImage out;
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.t_sensor_ns, 1'000'000'000);
  EXPECT_NEAR(out.depth_timestamp_s - out.timestamp_s, 0.005, 1e-9);

  // A stamp in the future of CLOCK_MONOTONIC (vivid's "Wrap Timestamp", flagged MONOTONIC): the
  // dequeue time is used instead, and counted.
  FakeV4l2Device wrapped;
  wrapped.nodes["/dev/video0"] = colourNode();
  wrapped.nodes["/dev/video0"].first_timestamp_ns = 4'294'967'280'000'000'000;
  wrapped.now_ns = 7'000'000'000;
  std::unique_ptr<V4l2Source> wrapped_source;
  ASSERT_TRUE(V4l2Source::open({}, camera4x2(), wrapped, &wrapped_source).ok());
  ASSERT_EQ(wrapped_source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.t_sensor_ns, 7'000'000'000);
  EXPECT_NE(wrapped_source->healthReport().find("dequeue-time stamps 1"), std::string::npos)
      << wrapped_source->healthReport();
  EXPECT_TRUE(timestampOnMonotonicClock(5'000'000'000, 6'000'000'000));
  EXPECT_FALSE(timestampOnMonotonicClock(5'000'000'000, 5'000'000'000 + kMaxBufferAgeNs + 1)) << "too old";
  EXPECT_FALSE(timestampOnMonotonicClock(0, 1'000'000'000)) << "no stamp";
}

}  // namespace
}  // namespace plumb
