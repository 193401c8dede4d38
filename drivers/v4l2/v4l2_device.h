#pragma once
// V4l2Device: the seam between V4L2 capture logic and the kernel. Every system call the capture
// makes goes through it, so tests drive the whole ioctl sequence with a fake device (including
// one that disappears mid-stream) and no camera. Calls follow the POSIX convention: -1 (or
// MAP_FAILED) with errno set on failure.
#include <sys/types.h>

#include <cstddef>
#include <cstdint>

namespace plumb {

class V4l2Device {
 public:
  virtual ~V4l2Device() = default;
  virtual int open(const char* path, int flags) = 0;
  virtual int close(int fd) = 0;
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  virtual void* mmap(std::size_t length, int fd, off_t offset) = 0;  // PROT_READ|WRITE, SHARED
  virtual int munmap(void* address, std::size_t length) = 0;
  // Waits until `fd` has a buffer ready: >0 ready, 0 timeout, -1 error (POLLERR/POLLHUP: errno
  // ENODEV after a hang-up, EIO otherwise; the caller's DQBUF then tells the driver's reason).
  virtual int poll(int fd, int timeout_ms) = 0;
  // CLOCK_MONOTONIC now, in ns: checks that a buffer's timestamp is on that clock (tests: fake).
  virtual int64_t monotonicNowNs() = 0;
};

// The real kernel interface (::open, ::ioctl retried on EINTR, ::mmap, ::poll).
V4l2Device& systemV4l2Device();

// "VIDIOC_DQBUF" for a request code, for error messages.
const char* v4l2RequestName(unsigned long request);

}  // namespace plumb
