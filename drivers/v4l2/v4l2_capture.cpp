#include "drivers/v4l2/v4l2_capture.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace plumb {
namespace {

uint32_t fourcc(V4l2PixelFormat format) {
  switch (format) {
    case V4l2PixelFormat::kYuyv: return V4L2_PIX_FMT_YUYV;
    case V4l2PixelFormat::kMjpeg: return V4L2_PIX_FMT_MJPEG;
    case V4l2PixelFormat::kGrey: return V4L2_PIX_FMT_GREY;
    case V4l2PixelFormat::kZ16: return V4L2_PIX_FMT_Z16;
    case V4l2PixelFormat::kY16: return V4L2_PIX_FMT_Y16;
  }
  return 0;
}

constexpr V4l2PixelFormat kAllFormats[] = {V4l2PixelFormat::kYuyv, V4l2PixelFormat::kMjpeg, V4l2PixelFormat::kGrey,
                                           V4l2PixelFormat::kZ16, V4l2PixelFormat::kY16};

// The format the driver answered, when plumb can take it in place of the one asked for.
bool acceptedSubstitute(V4l2PixelFormat asked, uint32_t offered, V4l2PixelFormat* got) {
  for (V4l2PixelFormat f : kAllFormats) {
    if (fourcc(f) != offered) continue;
    const bool depth_pair = (asked == V4l2PixelFormat::kZ16 && f == V4l2PixelFormat::kY16) ||
                            (asked == V4l2PixelFormat::kY16 && f == V4l2PixelFormat::kZ16);
    if (f == asked || depth_pair) {
      *got = f;
      return true;
    }
  }
  return false;
}

std::string fourccText(uint32_t code) {
  std::string s(4, ' ');
  for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((code >> (8 * i)) & 0xFF);
  return s;
}

}  // namespace

const char* pixelFormatName(V4l2PixelFormat format) {
  switch (format) {
    case V4l2PixelFormat::kYuyv: return "yuyv";
    case V4l2PixelFormat::kMjpeg: return "mjpeg";
    case V4l2PixelFormat::kGrey: return "grey";
    case V4l2PixelFormat::kZ16: return "z16";
    case V4l2PixelFormat::kY16: return "y16";
  }
  return "?";
}

bool timestampOnMonotonicClock(int64_t timestamp_ns, int64_t now_ns) {
  return timestamp_ns > 0 && timestamp_ns <= now_ns && now_ns - timestamp_ns <= kMaxBufferAgeNs;
}

bool parsePixelFormat(const std::string& name, V4l2PixelFormat* format) {
  for (V4l2PixelFormat f : kAllFormats) {
    if (name == pixelFormatName(f)) {
      *format = f;
      return true;
    }
  }
  return false;
}

Status V4l2Capture::fail(const char* what, int error_number) const {
  std::string message = options_.device_path + ": " + what + " failed: " + std::strerror(error_number);
  if (error_number == ENODEV || error_number == ENXIO) message += " (device disconnected)";
  return Status::Error(message);
}

Status V4l2Capture::open(const V4l2CaptureOptions& options) {
  close();
  options_ = options;
  have_previous_ = false;
  if (options.buffer_count < 2 || options.buffer_count > kMaxBuffers)
    return Status::Error(options.device_path + ": buffer_count must be 2.." +
                         std::to_string(kMaxBuffers));
  fd_ = device_.open(options.device_path.c_str(), O_RDWR | O_NONBLOCK);
  if (fd_ < 0) return fail("open", errno);

  v4l2_capability cap{};
  if (device_.ioctl(fd_, VIDIOC_QUERYCAP, &cap) < 0) {
    const Status st = fail("VIDIOC_QUERYCAP", errno);
    close();
    return st;
  }
  const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING)) {
    close();
    return Status::Error(options.device_path +
                         ": not a streaming video capture node (VIDIOC_QUERYCAP capabilities)");
  }

  v4l2_format fmt{};
  const Status format_status = negotiateFormat(&fmt);
  if (!format_status.ok()) {
    close();
    return format_status;
  }
  const std::size_t bytes_per_pixel =
      format_ == V4l2PixelFormat::kGrey ? 1 : (format_ == V4l2PixelFormat::kMjpeg ? 0 : 2);
  stride_ = fmt.fmt.pix.bytesperline ? fmt.fmt.pix.bytesperline : options.width * bytes_per_pixel;

  v4l2_streamparm parm{};  // frame rate: best effort, many drivers ignore or round it
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  parm.parm.capture.timeperframe.numerator = 1;
  parm.parm.capture.timeperframe.denominator = static_cast<uint32_t>(options.fps);
  (void)device_.ioctl(fd_, VIDIOC_S_PARM, &parm);

  v4l2_requestbuffers req{};
  req.count = static_cast<uint32_t>(options.buffer_count);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (device_.ioctl(fd_, VIDIOC_REQBUFS, &req) < 0) {
    const Status st = fail("VIDIOC_REQBUFS", errno);
    close();
    return st;
  }
  if (req.count < 2 || req.count > static_cast<uint32_t>(kMaxBuffers)) {
    close();
    return Status::Error(options.device_path + ": VIDIOC_REQBUFS granted " +
                         std::to_string(req.count) + " buffers (need 2.." +
                         std::to_string(kMaxBuffers) + ")");
  }
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (device_.ioctl(fd_, VIDIOC_QUERYBUF, &buf) < 0) {
      const Status st = fail("VIDIOC_QUERYBUF", errno);
      close();
      return st;
    }
    void* address = device_.mmap(buf.length, fd_, static_cast<off_t>(buf.m.offset));
    if (address == MAP_FAILED) {
      const Status st = fail("mmap", errno);
      close();
      return st;
    }
    (void)buffers_.push_back(MappedBuffer{address, buf.length});  // count <= kMaxBuffers
  }
  for (uint32_t i = 0; i < buffers_.size(); ++i) {
    const Status st = queueBuffer(i);
    if (!st.ok()) {
      close();
      return st;
    }
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (device_.ioctl(fd_, VIDIOC_STREAMON, &type) < 0) {
    const Status st = fail("VIDIOC_STREAMON", errno);
    close();
    return st;
  }
  streaming_ = true;
  return Status::Ok();
}

Status V4l2Capture::negotiateFormat(v4l2_format* fmt) {
  // Depth: Z16 first, then Y16 (same layout). A driver that cannot do a format either substitutes
  // another one (most) or refuses it with EINVAL (v4l2loopback, whose format its writer sets).
  const V4l2PixelFormat asked = options_.format;
  V4l2PixelFormat candidates[2] = {asked, asked};
  int count = 1;
  if (asked == V4l2PixelFormat::kZ16) candidates[count++] = V4l2PixelFormat::kY16;
  Status first_problem;
  for (int i = 0; i < count; ++i) {
    *fmt = v4l2_format{};
    fmt->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fmt->fmt.pix.width = static_cast<uint32_t>(options_.width);
    fmt->fmt.pix.height = static_cast<uint32_t>(options_.height);
    fmt->fmt.pix.pixelformat = fourcc(candidates[i]);
    fmt->fmt.pix.field = V4L2_FIELD_NONE;
    Status problem;
    if (device_.ioctl(fd_, VIDIOC_S_FMT, fmt) < 0) {
      problem = fail("VIDIOC_S_FMT", errno);
    } else if (acceptedSubstitute(asked, fmt->fmt.pix.pixelformat, &format_) &&
               fmt->fmt.pix.width == static_cast<uint32_t>(options_.width) &&
               fmt->fmt.pix.height == static_cast<uint32_t>(options_.height)) {
      return Status::Ok();
    } else {  // drivers adjust what they cannot do instead of failing: say what we got
      problem = Status::Error(options_.device_path + ": VIDIOC_S_FMT: asked for " + pixelFormatName(asked) + " " +
                              std::to_string(options_.width) + "x" + std::to_string(options_.height) +
                              ", driver offers " + fourccText(fmt->fmt.pix.pixelformat) + " " +
                              std::to_string(fmt->fmt.pix.width) + "x" + std::to_string(fmt->fmt.pix.height));
    }
    if (i == 0) first_problem = problem;
  }
  return first_problem;
}

Status V4l2Capture::queueBuffer(uint32_t index) {
  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buf.memory = V4L2_MEMORY_MMAP;
  buf.index = index;
  if (device_.ioctl(fd_, VIDIOC_QBUF, &buf) < 0) return fail("VIDIOC_QBUF", errno);
  return Status::Ok();
}

SourceResult V4l2Capture::dequeue(V4l2FrameView* view, Status* error) {
  if (fd_ < 0 || !streaming_) {
    *error = Status::Error(options_.device_path + ": not streaming");
    return SourceResult::kError;
  }
  if (dequeued_index_ >= 0) {
    *error = Status::Error(options_.device_path + ": previous buffer not requeued");
    return SourceResult::kError;
  }
  const int ready = device_.poll(fd_, options_.poll_timeout_ms);
  if (ready == 0) return SourceResult::kNoFrame;
  const int poll_errno = ready < 0 ? errno : 0;
  // Even when poll reports an error, DQBUF is asked: its errno is the driver's reason (ENODEV for
  // an unplugged node, EIO after a streaming error), and a buffer may still be waiting.
  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buf.memory = V4L2_MEMORY_MMAP;
  if (device_.ioctl(fd_, VIDIOC_DQBUF, &buf) < 0) {
    if (errno == EAGAIN && ready > 0) return SourceResult::kNoFrame;
    *error = errno == EAGAIN ? fail("poll", poll_errno) : fail("VIDIOC_DQBUF", errno);
    return SourceResult::kError;
  }
  if (buf.index >= buffers_.size() || buf.bytesused > buffers_[buf.index].length) {
    *error = Status::Error(options_.device_path + ": VIDIOC_DQBUF returned an invalid buffer");
    return SourceResult::kError;
  }
  if (buf.flags & V4L2_BUF_FLAG_ERROR) {
    // The driver says the content is damaged (a USB packet lost, an injected fault): it is never
    // delivered; its sequence number stays unused, so the frame counts as missing downstream.
    ++counters_.error_buffers;
    const Status st = queueBuffer(buf.index);
    if (!st.ok()) {
      *error = st;
      return SourceResult::kError;
    }
    return SourceResult::kNoFrame;
  }
  dequeued_index_ = static_cast<int>(buf.index);
  view->data = static_cast<const uint8_t*>(buffers_[buf.index].address);
  view->bytes_used = buf.bytesused;
  view->stride = stride_;
  const int64_t now_ns = device_.monotonicNowNs();
  const int64_t stamp_ns = static_cast<int64_t>(buf.timestamp.tv_sec) * 1000000000 +
                           static_cast<int64_t>(buf.timestamp.tv_usec) * 1000;
  if (timestampOnMonotonicClock(stamp_ns, now_ns)) {
    view->timestamp_ns = stamp_ns;
  } else {  // off the clock: the dequeue time is the best host-monotonic stamp we have
    view->timestamp_ns = now_ns;
    ++counters_.dequeue_time_stamps;
  }
  view->sequence = buf.sequence;
  ++counters_.buffers;
  const uint32_t step = buf.sequence - previous_sequence_;
  const int64_t elapsed_ns = view->timestamp_ns - previous_stamp_ns_;
  if (have_previous_ && step >= 1 && step <= 64 && elapsed_ns > 0) {
    const double period_ns = double(elapsed_ns) / step;
    observed_period_ns_ = observed_period_ns_ > 0 ? 0.9 * observed_period_ns_ + 0.1 * period_ns : period_ns;
  }
  have_previous_ = true;
  previous_stamp_ns_ = view->timestamp_ns;
  previous_sequence_ = buf.sequence;
  return SourceResult::kFrame;
}

Status V4l2Capture::requeue() {
  if (dequeued_index_ < 0) return Status::Ok();
  const uint32_t index = static_cast<uint32_t>(dequeued_index_);
  dequeued_index_ = -1;
  return queueBuffer(index);
}

void V4l2Capture::close() {
  if (fd_ < 0) return;
  if (streaming_) {
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    (void)device_.ioctl(fd_, VIDIOC_STREAMOFF, &type);  // fails harmlessly on a vanished device
    streaming_ = false;
  }
  for (const MappedBuffer& b : buffers_) (void)device_.munmap(b.address, b.length);
  buffers_.clear();
  dequeued_index_ = -1;
  (void)device_.close(fd_);
  fd_ = -1;
}

}  // namespace plumb
