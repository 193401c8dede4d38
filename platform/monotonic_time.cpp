#include "platform/monotonic_time.h"

#include <cerrno>
#include <ctime>

namespace plumb {

namespace {
constexpr int64_t kNsPerSecond = 1'000'000'000;
}

int64_t monotonicNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

void sleepUntilMonotonicNs(int64_t t_ns) {
  if (t_ns <= monotonicNowNs()) return;
  timespec deadline{};
  deadline.tv_sec = static_cast<time_t>(t_ns / kNsPerSecond);
  deadline.tv_nsec = static_cast<long>(t_ns % kNsPerSecond);
  // An absolute deadline: a signal that interrupts the sleep simply restarts it with the same target.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
  }
}

}  // namespace plumb
