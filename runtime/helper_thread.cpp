#include "runtime/helper_thread.h"

#include <system_error>

namespace plumb::runtime {

HelperThread::~HelperThread() {
  if (!thread_.joinable()) return;
  waitDone();
  stop_.store(true, std::memory_order_release);
  posted_bell_.ring();
  thread_.join();
}

bool HelperThread::started() {
  if (thread_.joinable()) return true;
  if (unavailable_) return false;
  try {
    thread_ = std::thread([this] { helperMain(); });
  } catch (const std::system_error&) {
    unavailable_ = true;
  }
  return !unavailable_;
}

void HelperThread::post(void (*job)(void*), void* context) {
  job_ = job;
  context_ = context;
  posted_.fetch_add(1, std::memory_order_release);
  posted_bell_.ring();
}

void HelperThread::waitDone() {
  const uint64_t target = posted_.load(std::memory_order_relaxed);
  done_bell_.waitUntil([&] { return done_.load(std::memory_order_acquire) == target; });
}

void HelperThread::helperMain() {
  uint64_t seen = 0;
  for (;;) {
    posted_bell_.waitUntil([&] {
      return posted_.load(std::memory_order_acquire) != seen || stop_.load(std::memory_order_acquire);
    });
    if (posted_.load(std::memory_order_acquire) == seen) return;  // stop, nothing pending
    seen = posted_.load(std::memory_order_acquire);
    job_(context_);
    done_.store(seen, std::memory_order_release);
    done_bell_.ring();
  }
}

}  // namespace plumb::runtime
