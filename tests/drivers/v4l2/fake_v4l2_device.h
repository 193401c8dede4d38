#pragma once
// FakeV4l2Device: an in-memory V4L2 driver for tests. Each node (path) has one format, a frame
// generator, timestamps at a fixed period, and switches for faults: an ioctl that fails with an
// errno, a format the "driver" substitutes, and unplugging (DQBUF -> ENODEV, open -> ENODEV).
// Every call is logged ("open /dev/video0", "VIDIOC_QBUF", "mmap", ...) so tests can check the
// exact sequence the capture code issues.
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "drivers/v4l2/v4l2_device.h"

namespace plumb::test {

struct FakeV4l2Node {
  uint32_t fourcc = V4L2_PIX_FMT_YUYV;
  uint32_t width = 4, height = 2;
  uint32_t bytes_per_line = 8;
  uint32_t offered_width = 0;  // non-zero: S_FMT answers with this width instead (driver adjusts)
  bool refuses_other_formats = false;  // S_FMT of another fourcc fails with EINVAL (v4l2loopback)
  int64_t first_timestamp_ns = 1'000'000'000;
  int64_t period_ns = 33'333'333;
  // Fills frame number k (k counts every frame the "sensor" produced, including unplugged time).
  std::function<void(uint64_t k, uint8_t* data, std::size_t length, uint32_t* bytes_used)> fill;
  // Faults.
  unsigned long failing_request = 0;  // this ioctl fails with failing_errno
  int failing_errno = EINVAL;
  int unplug_after_dequeues = -1;     // DQBUF number n (0-based) fails with ENODEV; -1 never
  bool unplugged = false;             // open() fails with ENODEV while set
  std::vector<uint64_t> error_frames;  // frames returned with V4L2_BUF_FLAG_ERROR
  int queue_error_after_dequeues = -1;  // then poll -> POLLERR (EIO) and DQBUF -> EIO until STREAMOFF
  bool queue_error = false;
  uint32_t timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  uint32_t first_sequence = 0;        // the driver's counter for frame 0 (wrap tests)
  // State.
  std::vector<std::vector<uint8_t>> buffers;
  std::deque<uint32_t> queued;
  bool streaming = false;
  int dequeues = 0;
  uint64_t produced = 0;  // frames the sensor has produced (advanced also while unplugged)
};

class FakeV4l2Device : public V4l2Device {
 public:
  std::map<std::string, FakeV4l2Node> nodes;
  std::vector<std::string> log;
  bool logging = true;  // off for allocation tests (the log itself allocates)
  int live_mappings = 0;
  int open_fds = 0;
  // CLOCK_MONOTONIC as the fake reports it: 0 = 1 ms after the newest timestamp handed out (frames
  // are then always fresh); tests set it to age frames or to put the clock elsewhere.
  int64_t now_ns = 0;
  int64_t newest_timestamp_ns = 0;

  int64_t monotonicNowNs() override { return now_ns != 0 ? now_ns : newest_timestamp_ns + 1'000'000; }

  int open(const char* path, int) override {
    note(std::string("open ") + path);
    auto it = nodes.find(path);
    if (it == nodes.end()) return fail(ENOENT);
    if (it->second.unplugged) return fail(ENODEV);
    const int fd = next_fd_++;
    fds_[fd] = path;
    ++open_fds;
    return fd;
  }
  int close(int fd) override {
    note("close");
    if (!fds_.erase(fd)) return fail(EBADF);
    --open_fds;
    return 0;
  }
  void* mmap(std::size_t length, int fd, off_t offset) override {
    note("mmap");
    FakeV4l2Node* n = node(fd);
    const std::size_t index = static_cast<std::size_t>(offset) / kPage;
    if (!n || index >= n->buffers.size() || length != n->buffers[index].size()) {
      errno = EINVAL;
      return MAP_FAILED;
    }
    ++live_mappings;
    return n->buffers[index].data();
  }
  int munmap(void*, std::size_t) override {
    note("munmap");
    --live_mappings;
    return 0;
  }
  int poll(int fd, int) override {
    note("poll");
    FakeV4l2Node* n = node(fd);
    if (!n) return fail(EBADF);
    armQueueError(*n);
    if (n->queue_error) return fail(EIO);  // what the system device reports for POLLERR alone
    return n->queued.empty() ? 0 : 1;
  }

  int ioctl(int fd, unsigned long request, void* arg) override {
    note(v4l2RequestName(request));
    FakeV4l2Node* n = node(fd);
    if (!n) return fail(EBADF);
    if (request == n->failing_request) return fail(n->failing_errno);
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* cap = static_cast<v4l2_capability*>(arg);
        std::memset(cap, 0, sizeof *cap);
        cap->capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
        return 0;
      }
      case VIDIOC_S_FMT: {
        auto* fmt = static_cast<v4l2_format*>(arg);
        if (n->refuses_other_formats && fmt->fmt.pix.pixelformat != n->fourcc) return fail(EINVAL);
        fmt->fmt.pix.pixelformat = n->fourcc;
        fmt->fmt.pix.width = n->offered_width ? n->offered_width : n->width;
        fmt->fmt.pix.height = n->height;
        fmt->fmt.pix.bytesperline = n->bytes_per_line;
        return 0;
      }
      case VIDIOC_S_PARM: return 0;
      case VIDIOC_REQBUFS: {
        auto* req = static_cast<v4l2_requestbuffers*>(arg);
        n->buffers.assign(req->count, std::vector<uint8_t>(n->bytes_per_line * n->height * 2));
        n->queued.clear();
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* buf = static_cast<v4l2_buffer*>(arg);
        if (buf->index >= n->buffers.size()) return fail(EINVAL);
        buf->length = static_cast<uint32_t>(n->buffers[buf->index].size());
        buf->m.offset = buf->index * kPage;
        return 0;
      }
      case VIDIOC_QBUF: {
        auto* buf = static_cast<v4l2_buffer*>(arg);
        if (buf->index >= n->buffers.size()) return fail(EINVAL);
        n->queued.push_back(buf->index);
        return 0;
      }
      case VIDIOC_STREAMON: n->streaming = true; return 0;
      case VIDIOC_STREAMOFF:
        n->streaming = false;
        n->queue_error = false;
        n->queued.clear();
        return 0;
      case VIDIOC_DQBUF: {
        if (n->unplug_after_dequeues >= 0 && n->dequeues >= n->unplug_after_dequeues) {
          n->unplugged = true;
          n->unplug_after_dequeues = -1;
          return fail(ENODEV);
        }
        if (n->unplugged) return fail(ENODEV);
        armQueueError(*n);
        if (n->queue_error) return fail(EIO);
        if (!n->streaming || n->queued.empty()) return fail(EAGAIN);
        auto* buf = static_cast<v4l2_buffer*>(arg);
        buf->index = n->queued.front();
        n->queued.pop_front();
        const uint64_t k = n->produced++;
        uint32_t used = n->bytes_per_line * n->height;
        if (n->fill) n->fill(k, n->buffers[buf->index].data(), n->buffers[buf->index].size(), &used);
        buf->bytesused = used;
        buf->sequence = static_cast<uint32_t>(n->first_sequence + k);
        buf->flags = n->timestamp_flags;
        for (uint64_t e : n->error_frames) buf->flags |= e == k ? V4L2_BUF_FLAG_ERROR : 0;
        const int64_t t = n->first_timestamp_ns + static_cast<int64_t>(k) * n->period_ns;
        newest_timestamp_ns = std::max(newest_timestamp_ns, t);
        buf->timestamp.tv_sec = t / 1000000000;
        buf->timestamp.tv_usec = (t % 1000000000) / 1000;
        ++n->dequeues;
        return 0;
      }
      default: return fail(ENOTTY);
    }
  }

  void note(const std::string& entry) {
    if (logging) log.push_back(entry);
  }
  void note(const char* entry) {
    if (logging) log.push_back(entry);
  }

  // Number of log entries equal to `entry`.
  int count(const std::string& entry) const {
    int c = 0;
    for (const auto& e : log) c += e == entry;
    return c;
  }

 private:
  static constexpr std::size_t kPage = 4096;
  static void armQueueError(FakeV4l2Node& n) {
    if (n.queue_error_after_dequeues >= 0 && n.dequeues >= n.queue_error_after_dequeues) {
      n.queue_error = true;
      n.queue_error_after_dequeues = -1;
    }
  }
  static int fail(int e) {
    errno = e;
    return -1;
  }
  FakeV4l2Node* node(int fd) {
    auto it = fds_.find(fd);
    return it == fds_.end() ? nullptr : &nodes[it->second];
  }
  std::map<int, std::string> fds_;
  int next_fd_ = 3;
};

}  // namespace plumb::test
