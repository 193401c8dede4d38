#pragma once
// The runtime's injectable clock. Stages are timed and replay is paced through a Clock&, never
// through the system clock directly, so tests can swap in a VirtualClock and make pacing, latency
// and frame dropping exactly reproducible.
//
//   MonotonicClock  real time (CLOCK_MONOTONIC); sleepUntilNs really sleeps.
//   VirtualClock    time is a number that only moves when told: sleepUntilNs jumps forward, a
//                   test stage "takes" 25 ms by calling advanceNs(25'000'000). A realtime run on a
//                   VirtualClock is simulated event by event (see stage_runner.h), because threads
//                   racing on one virtual time could not be reproducible.
#include <atomic>
#include <cstdint>

namespace plumb::runtime {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual int64_t nowNs() const = 0;
  // Blocks (or, for a virtual clock, jumps) until nowNs() >= t_ns. Returns at once if already past.
  virtual void sleepUntilNs(int64_t t_ns) = 0;
  virtual bool isVirtual() const { return false; }
};

class MonotonicClock final : public Clock {
 public:
  int64_t nowNs() const override;
  void sleepUntilNs(int64_t t_ns) override;
};

// Process-wide real clock, the default of every runner.
MonotonicClock& monotonicClock();

class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(int64_t start_ns = 0) : now_ns_(start_ns) {}
  int64_t nowNs() const override { return now_ns_.load(std::memory_order_acquire); }
  void sleepUntilNs(int64_t t_ns) override;
  bool isVirtual() const override { return true; }

  // A stage pretending to compute for duration_ns.
  void advanceNs(int64_t duration_ns) { now_ns_.fetch_add(duration_ns, std::memory_order_acq_rel); }
  // Sets the time outright (also backwards): the event simulation places the clock at the start of
  // each simulated step.
  void setNs(int64_t t_ns) { now_ns_.store(t_ns, std::memory_order_release); }

 private:
  // Atomic so that threaded runs may read it (for stamps) without a data race; only the
  // simulation's single thread moves it backwards.
  std::atomic<int64_t> now_ns_;
};

}  // namespace plumb::runtime
