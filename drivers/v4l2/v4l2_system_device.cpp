#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>

#include "drivers/v4l2/v4l2_device.h"

namespace plumb {
namespace {

class SystemV4l2Device : public V4l2Device {
 public:
  int open(const char* path, int flags) override { return ::open(path, flags | O_CLOEXEC); }
  int close(int fd) override { return ::close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override {
    int r;
    do {
      r = ::ioctl(fd, request, arg);
    } while (r == -1 && errno == EINTR);
    return r;
  }
  void* mmap(std::size_t length, int fd, off_t offset) override {
    return ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
  }
  int munmap(void* address, std::size_t length) override { return ::munmap(address, length); }
  int poll(int fd, int timeout_ms) override {
    pollfd p{fd, POLLIN, 0};
    int r;
    do {
      r = ::poll(&p, 1, timeout_ms);
    } while (r == -1 && errno == EINTR);
    if (r > 0 && (p.revents & (POLLERR | POLLHUP | POLLNVAL)) && !(p.revents & POLLIN)) {
      // An unregistered (unplugged) node reports POLLERR|POLLHUP; a streaming error in the driver
      // (vb2_queue_error) only POLLERR. Either way DQBUF then says what happened.
      errno = (p.revents & (POLLHUP | POLLNVAL)) ? ENODEV : EIO;
      return -1;
    }
    return r;
  }
  int64_t monotonicNowNs() override {
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    return static_cast<int64_t>(now.tv_sec) * 1000000000 + now.tv_nsec;
  }
};

}  // namespace

V4l2Device& systemV4l2Device() {
  static SystemV4l2Device device;
  return device;
}

const char* v4l2RequestName(unsigned long request) {
  switch (request) {
    case VIDIOC_QUERYCAP: return "VIDIOC_QUERYCAP";
    case VIDIOC_S_FMT: return "VIDIOC_S_FMT";
    case VIDIOC_G_FMT: return "VIDIOC_G_FMT";
    case VIDIOC_S_PARM: return "VIDIOC_S_PARM";
    case VIDIOC_REQBUFS: return "VIDIOC_REQBUFS";
    case VIDIOC_QUERYBUF: return "VIDIOC_QUERYBUF";
    case VIDIOC_QBUF: return "VIDIOC_QBUF";
    case VIDIOC_DQBUF: return "VIDIOC_DQBUF";
    case VIDIOC_STREAMON: return "VIDIOC_STREAMON";
    case VIDIOC_STREAMOFF: return "VIDIOC_STREAMOFF";
    default: return "ioctl";
  }
}

}  // namespace plumb
