#include "platform/memory_lock.h"

#include <sys/mman.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

namespace plumb {

Status lockProcessMemory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return Status::Ok();
  const int err = errno;
  std::string why = std::strerror(err);
  if (err == EPERM || err == ENOMEM) {
    why += " (needs CAP_IPC_LOCK or a larger RLIMIT_MEMLOCK, see `ulimit -l`)";
  }
  return Status::Error("cannot lock process memory with mlockall: " + why);
}

bool lockProcessMemoryOrWarn() {
  static std::atomic<bool> warned{false};
  const Status status = lockProcessMemory();
  if (!status.ok() && !warned.exchange(true)) {
    std::fprintf(stderr, "plumb: warning: %s (continuing unlocked)\n", status.message().c_str());
  }
  return status.ok();
}

void unlockProcessMemory() { munlockall(); }

}  // namespace plumb
