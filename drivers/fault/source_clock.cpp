#include "drivers/fault/source_clock.h"

#include <chrono>
#include <thread>

namespace plumb {
namespace {

class SteadyClock : public SourceClock {
 public:
  int64_t nowNs() override {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  void sleepForNs(int64_t duration_ns) override {
    if (duration_ns > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(duration_ns));
  }
};

}  // namespace

SourceClock& steadyClock() {
  static SteadyClock clock;
  return clock;
}

}  // namespace plumb
