#include "runtime/thread_nice.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace plumb::runtime {

Status setCurrentThreadNice(int nice_value) {
  // PRIO_PROCESS with a thread id addresses that one thread on Linux.
  const auto tid = static_cast<id_t>(::syscall(SYS_gettid));
  if (::setpriority(PRIO_PROCESS, tid, nice_value) != 0) {
    return Status::Error("setpriority(nice " + std::to_string(nice_value) + "): " + std::strerror(errno));
  }
  return Status::Ok();
}

}  // namespace plumb::runtime
