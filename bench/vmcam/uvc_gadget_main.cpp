// plumb_vmcam_uvc_gadget: the userspace half of a UVC camera gadget (usb_f_uvc configured through
// configfs by scripts/vm_camera_guest.sh), for the virtual-machine camera bench. The kernel function
// forwards the host's UVC class requests and stream starts as V4L2 events on its video output
// node; this program answers them (one YUYV 320x240 format at 15 Hz: probe/commit) and, while the
// host streams, fills the node's buffers with a moving test pattern. Stops after --seconds S.
//   plumb_vmcam_uvc_gadget --device /dev/videoN [--seconds S (30)]
// Prints what it saw: requests answered, stream on/off, frames queued. Exit 1 on a node error.
#include <fcntl.h>
#include <linux/usb/ch9.h>
#include <linux/usb/g_uvc.h>
#include <linux/usb/video.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "retry_ioctl.h"

namespace {

// What the configfs function announces (scripts/vm_camera_guest.sh make_gadget): YUYV 320x240 at
// 15 Hz, small enough for USB/IP under an emulated CPU.
constexpr int kWidth = 320, kHeight = 240;
constexpr uint32_t kFrameBytes = kWidth * kHeight * 2;
constexpr uint32_t kInterval100ns = 666666;  // 15 Hz
constexpr int kBuffers = 4;

// Failure is a negative result: usb_f_uvc's VIDIOC_REQBUFS returns the buffer count (6.1).
using plumb::vmcam::retryIoctl;

struct Gadget {
  int fd = -1;
  std::vector<std::pair<void*, size_t>> buffers;
  bool streaming = false;
  uint8_t control_selector = 0;  // the SET_CUR whose data phase comes next
  uint64_t frames = 0, requests = 0, stalls = 0, stream_ons = 0;

  void fillControl(uvc_streaming_control* c) const {
    std::memset(c, 0, sizeof *c);
    c->bmHint = 1;
    c->bFormatIndex = 1;
    c->bFrameIndex = 1;
    c->dwFrameInterval = kInterval100ns;
    c->dwMaxVideoFrameSize = kFrameBytes;
    c->dwMaxPayloadTransferSize = 3072;  // streaming_maxpacket (configfs)
    c->bmFramingInfo = 3;
    c->bPreferedVersion = c->bMinVersion = c->bMaxVersion = 1;
  }

  void fill(void* data) {
    auto* p = static_cast<uint8_t*>(data);
    for (int r = 0; r < kHeight; ++r)
      for (int c = 0; c < kWidth; c += 2, p += 4) {
        p[0] = p[2] = uint8_t(16 + ((r + c + frames * 4) % 220));
        p[1] = p[3] = 128;
      }
  }

  bool queue(uint32_t index) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = index;
    fill(buffers[index].first);
    b.bytesused = kFrameBytes;
    if (retryIoctl(fd, VIDIOC_QBUF, &b) < 0) {
      std::fprintf(stderr, "uvc gadget: VIDIOC_QBUF: %s\n", std::strerror(errno));
      return false;
    }
    ++frames;
    return true;
  }

  bool streamOn() {
    ++stream_ons;
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    fmt.fmt.pix.width = kWidth;
    fmt.fmt.pix.height = kHeight;
    fmt.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    fmt.fmt.pix.sizeimage = kFrameBytes;
    if (retryIoctl(fd, VIDIOC_S_FMT, &fmt) < 0) return report("VIDIOC_S_FMT");
    v4l2_requestbuffers req{};
    req.count = kBuffers;
    req.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    req.memory = V4L2_MEMORY_MMAP;
    if (retryIoctl(fd, VIDIOC_REQBUFS, &req) < 0) return report("VIDIOC_REQBUFS");
    for (uint32_t i = 0; i < req.count; ++i) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = i;
      if (retryIoctl(fd, VIDIOC_QUERYBUF, &b) < 0) return report("VIDIOC_QUERYBUF");
      void* p = mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, b.m.offset);
      if (p == MAP_FAILED) return report("mmap");
      buffers.emplace_back(p, b.length);
    }
    for (uint32_t i = 0; i < buffers.size(); ++i)
      if (!queue(i)) return false;
    int type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    if (retryIoctl(fd, VIDIOC_STREAMON, &type) < 0) return report("VIDIOC_STREAMON");
    streaming = true;
    std::printf("uvc gadget: host started streaming\n");
    return true;
  }

  void streamOff() {
    int type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    retryIoctl(fd, VIDIOC_STREAMOFF, &type);
    for (auto& b : buffers) munmap(b.first, b.second);
    buffers.clear();
    v4l2_requestbuffers req{};
    req.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    req.memory = V4L2_MEMORY_MMAP;
    retryIoctl(fd, VIDIOC_REQBUFS, &req);
    if (streaming) std::printf("uvc gadget: host stopped streaming after %llu frames\n", (unsigned long long)frames);
    streaming = false;
  }

  bool report(const char* what) {
    std::fprintf(stderr, "uvc gadget: %s failed: %s\n", what, std::strerror(errno));
    return false;
  }

  // A class request from the host: probe/commit on the streaming interface are answered; every
  // other request (camera controls) is stalled, which UVC hosts accept.
  void setup(const usb_ctrlrequest& req) {
    ++requests;
    uvc_request_data resp{};
    const uint8_t selector = uint8_t(req.wValue >> 8);
    const uint8_t interface = uint8_t(req.wIndex & 0xff);
    const bool streaming_interface = interface != 0;
    if ((req.bRequestType & USB_TYPE_MASK) != USB_TYPE_CLASS || !streaming_interface ||
        (selector != UVC_VS_PROBE_CONTROL && selector != UVC_VS_COMMIT_CONTROL)) {
      resp.length = -EL2HLT;
      ++stalls;
    } else if (req.bRequest == UVC_SET_CUR) {
      control_selector = selector;
      resp.length = req.wLength;
    } else if (req.bRequest == UVC_GET_INFO) {
      resp.data[0] = 0x03;  // GET and SET supported
      resp.length = 1;
    } else if (req.bRequest == UVC_GET_LEN) {
      resp.data[0] = sizeof(uvc_streaming_control);
      resp.length = 2;
    } else {  // GET_CUR, GET_MIN, GET_MAX, GET_DEF, GET_RES: one format, one frame size, one rate
      uvc_streaming_control c;
      fillControl(&c);
      resp.length = std::min<int>(req.wLength, sizeof c);
      std::memcpy(resp.data, &c, size_t(resp.length));
    }
    if (retryIoctl(fd, UVCIOC_SEND_RESPONSE, &resp) < 0) report("UVCIOC_SEND_RESPONSE");
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string device;
  double seconds = 30;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--device") == 0) device = argv[i + 1];
    else if (std::strcmp(argv[i], "--seconds") == 0) seconds = std::atof(argv[i + 1]);
  }
  if (device.empty()) {
    std::fprintf(stderr, "usage: %s --device /dev/videoN [--seconds S]\n", argv[0]);
    return 2;
  }
  Gadget g;
  g.fd = open(device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (g.fd < 0) {
    std::fprintf(stderr, "uvc gadget: %s: %s\n", device.c_str(), std::strerror(errno));
    return 1;
  }
  for (uint32_t type : {UVC_EVENT_CONNECT, UVC_EVENT_DISCONNECT, UVC_EVENT_SETUP, UVC_EVENT_DATA,
                        UVC_EVENT_STREAMON, UVC_EVENT_STREAMOFF}) {
    v4l2_event_subscription sub{};
    sub.type = type;
    if (retryIoctl(g.fd, VIDIOC_SUBSCRIBE_EVENT, &sub) < 0) return g.report("VIDIOC_SUBSCRIBE_EVENT") ? 0 : 1;
  }
  std::printf("uvc gadget: serving %s\n", device.c_str());
  std::fflush(stdout);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    pollfd p{g.fd, short(POLLPRI | (g.streaming ? POLLOUT : 0)), 0};
    if (poll(&p, 1, 100) <= 0) continue;
    if (p.revents & POLLPRI) {
      v4l2_event ev{};
      if (retryIoctl(g.fd, VIDIOC_DQEVENT, &ev) != 0) continue;
      const auto* uvc = reinterpret_cast<const uvc_event*>(&ev.u.data);
      switch (ev.type) {
        case UVC_EVENT_SETUP: g.setup(uvc->req); break;
        case UVC_EVENT_DATA: break;  // the host's probe/commit values: our single mode regardless
        case UVC_EVENT_STREAMON:
          if (!g.streamOn()) g.streamOff();
          break;
        case UVC_EVENT_STREAMOFF:
        case UVC_EVENT_DISCONNECT: g.streamOff(); break;
        default: break;
      }
    }
    if (g.streaming && (p.revents & POLLOUT)) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
      b.memory = V4L2_MEMORY_MMAP;
      if (retryIoctl(g.fd, VIDIOC_DQBUF, &b) == 0) g.queue(b.index);
    }
    std::fflush(stdout);
  }
  g.streamOff();
  std::printf("uvc gadget: %llu requests (%llu stalled), %llu stream starts, %llu frames queued\n",
              (unsigned long long)g.requests, (unsigned long long)g.stalls, (unsigned long long)g.stream_ons,
              (unsigned long long)g.frames);
  close(g.fd);
  return 0;
}
