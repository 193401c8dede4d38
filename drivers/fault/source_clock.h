#pragma once
// SourceClock: the time seam of source wrappers (fault supervision backoff, replay pacing).
// Production code uses steadyClock() (CLOCK_MONOTONIC via std::chrono::steady_clock); tests use
// VirtualClock, whose sleeps advance time instantly, so backoff and pacing tests take no time.
#include <cstdint>
#include <vector>

namespace plumb {

class SourceClock {
 public:
  virtual ~SourceClock() = default;
  virtual int64_t nowNs() = 0;
  virtual void sleepForNs(int64_t duration_ns) = 0;  // non-positive durations return at once
};

// The process-wide monotonic clock.
SourceClock& steadyClock();

// Deterministic clock for tests: time moves only through sleepForNs() and advance().
class VirtualClock : public SourceClock {
 public:
  explicit VirtualClock(int64_t start_ns = 0) : now_ns_(start_ns) {}
  int64_t nowNs() override { return now_ns_; }
  void sleepForNs(int64_t duration_ns) override {
    if (duration_ns <= 0) return;
    sleeps_ns.push_back(duration_ns);
    now_ns_ += duration_ns;
  }
  void advance(int64_t duration_ns) { now_ns_ += duration_ns; }
  std::vector<int64_t> sleeps_ns;  // every sleep requested, in order

 private:
  int64_t now_ns_;
};

}  // namespace plumb
