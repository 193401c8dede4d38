#include "runtime/clock.h"

#include "platform/monotonic_time.h"

namespace plumb::runtime {

int64_t MonotonicClock::nowNs() const { return monotonicNowNs(); }

void MonotonicClock::sleepUntilNs(int64_t t_ns) { sleepUntilMonotonicNs(t_ns); }

MonotonicClock& monotonicClock() {
  static MonotonicClock clock;
  return clock;
}

void VirtualClock::sleepUntilNs(int64_t t_ns) {
  int64_t now = now_ns_.load(std::memory_order_acquire);
  // Only ever forward: a concurrent advanceNs must not be undone.
  while (now < t_ns &&
         !now_ns_.compare_exchange_weak(now, t_ns, std::memory_order_acq_rel)) {
  }
}

}  // namespace plumb::runtime
