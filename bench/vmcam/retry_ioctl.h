#pragma once
// ioctl retried while a signal interrupts it (EINTR), for the bench/vmcam programs.
#include <sys/ioctl.h>

#include <cerrno>

namespace plumb::vmcam {

inline int retryIoctl(int fd, unsigned long request, void* arg) {
  int r;
  do {
    r = ioctl(fd, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

}  // namespace plumb::vmcam
