#pragma once
// V4l2Capture: one V4L2 video node streaming into memory-mapped buffers, allocated once at open:
//   open -> VIDIOC_QUERYCAP -> VIDIOC_S_FMT -> VIDIOC_S_PARM (frame rate, best effort)
//        -> VIDIOC_REQBUFS -> VIDIOC_QUERYBUF + mmap per buffer -> VIDIOC_QBUF all
//        -> VIDIOC_STREAMON;  per frame: poll -> VIDIOC_DQBUF ... VIDIOC_QBUF;
//   close: VIDIOC_STREAMOFF -> munmap -> close.
// Every failure names the device and the ioctl, e.g. "/dev/video2: VIDIOC_DQBUF failed: No such
// device (device disconnected)".
#include <linux/videodev2.h>

#include <cstdint>
#include <string>

#include "drivers/common/frame_source.h"
#include "drivers/v4l2/v4l2_device.h"
#include "platform/fixed_vector.h"
#include "platform/status.h"

namespace plumb {

// kY16 ('Y16 ', 16-bit little-endian grey) is accepted in place of kZ16 on a depth node: same
// layout, and the format v4l2loopback and some depth cameras announce for depth.
enum class V4l2PixelFormat { kYuyv, kMjpeg, kGrey, kZ16, kY16 };

// "yuyv", "mjpeg", "grey", "z16", "y16".
const char* pixelFormatName(V4l2PixelFormat format);
bool parsePixelFormat(const std::string& name, V4l2PixelFormat* format);

struct V4l2CaptureOptions {
  std::string device_path;  // e.g. /dev/video0
  V4l2PixelFormat format = V4l2PixelFormat::kYuyv;
  int width = 640, height = 480;
  int fps = 30;
  int buffer_count = 4;       // enough to hold one for pairing while the driver fills the rest
  int poll_timeout_ms = 100;  // kNoFrame after this long without a buffer (3 frames at 30 Hz)
};

// A dequeued buffer, valid until requeue().
struct V4l2FrameView {
  const uint8_t* data = nullptr;
  std::size_t bytes_used = 0;
  std::size_t stride = 0;     // bytes per line
  // The buffer's kernel timestamp when it is on CLOCK_MONOTONIC (see timestampOnMonotonicClock),
  // else the dequeue time.
  int64_t timestamp_ns = 0;
  uint32_t sequence = 0;      // driver frame counter (gaps = frames the driver dropped)
};

// What a node's driver did, counted over the capture's life (reopens included).
struct V4l2CaptureCounters {
  uint64_t buffers = 0;              // buffers delivered to the caller
  uint64_t error_buffers = 0;        // flagged V4L2_BUF_FLAG_ERROR: given back unread
  uint64_t dequeue_time_stamps = 0;  // delivered with the dequeue time (their own was off the clock)
};

// A buffer timestamp is used as the frame's time only when it can be on CLOCK_MONOTONIC: not in
// the future and at most kMaxBufferAgeNs old at dequeue. The V4L2 flag alone is not enough: vivid's
// "Wrap Timestamp" flags MONOTONIC stamps that are far off that clock, and v4l2loopback stamps with
// ktime_get_ts64 (monotonic) but flags the clock unknown. Two nodes of one camera stamped this way
// can be paired by their kernel times.
constexpr int64_t kMaxBufferAgeNs = 2'000'000'000;
bool timestampOnMonotonicClock(int64_t timestamp_ns, int64_t now_ns);

class V4l2Capture {
 public:
  static constexpr int kMaxBuffers = 16;

  explicit V4l2Capture(V4l2Device& device) : device_(device) {}
  ~V4l2Capture() { close(); }
  V4l2Capture(const V4l2Capture&) = delete;
  V4l2Capture& operator=(const V4l2Capture&) = delete;

  Status open(const V4l2CaptureOptions& options);
  // kFrame: *view is valid until requeue(). kNoFrame: poll timed out. kError: *error says why.
  SourceResult dequeue(V4l2FrameView* view, Status* error);
  Status requeue();  // gives the buffer of the last dequeue() back to the driver
  void close();      // best effort, never fails: also used after the device vanished
  bool isOpen() const { return fd_ >= 0; }
  const V4l2CaptureOptions& options() const { return options_; }
  // The format the driver streams (options().format, or kY16 standing in for kZ16).
  V4l2PixelFormat format() const { return format_; }
  const V4l2CaptureCounters& counters() const { return counters_; }
  // The node's frame period as its buffers show it (stamp difference over sequence difference, a
  // running mean over ~10 buffers; kept across reopens), 0 until two buffers were seen. Cameras
  // may run slower than the rate asked with VIDIOC_S_PARM, which drivers are free to ignore.
  double observedPeriodNs() const { return observed_period_ns_; }

 private:
  struct MappedBuffer {
    void* address = nullptr;
    std::size_t length = 0;
  };
  Status fail(const char* what, int error_number) const;
  // VIDIOC_S_FMT with options_.format (for Z16 also Y16); sets format_ and fills *fmt.
  Status negotiateFormat(v4l2_format* fmt);
  Status queueBuffer(uint32_t index);

  V4l2Device& device_;
  V4l2CaptureOptions options_;
  int fd_ = -1;
  bool streaming_ = false;
  V4l2PixelFormat format_ = V4l2PixelFormat::kYuyv;
  V4l2CaptureCounters counters_;
  bool have_previous_ = false;  // a buffer was delivered since open()
  int64_t previous_stamp_ns_ = 0;
  uint32_t previous_sequence_ = 0;
  double observed_period_ns_ = 0;
  std::size_t stride_ = 0;
  FixedVector<MappedBuffer, kMaxBuffers> buffers_;
  int dequeued_index_ = -1;  // buffer held by the caller, -1 = none
};

}  // namespace plumb
