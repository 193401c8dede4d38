#pragma once
// Doorbell: how a stage thread waits for work without burning a core and without sleep-polling.
//
// The waiter checks its condition (e.g. "my input ring is not empty"); if false it spins briefly
// (work usually arrives within microseconds in a busy pipeline), then sleeps on a futex. The
// notifier publishes its data (e.g. try_push), then ring()s: it bumps epoch_ and, only if somebody
// is asleep, makes the wake system call, so an uncontended push costs one atomic increment.
//
// Why this cannot lose a wake-up: the waiter registers in sleepers_ and reads epoch_ *before* its
// final check of the condition, and futexWait(epoch_, seen) refuses to sleep once epoch_ has moved.
// The notifier bumps epoch_ *after* publishing and reads sleepers_ after that; all four operations
// are seq_cst, so either the notifier sees the sleeper (and wakes it), or the waiter's epoch read
// comes after the bump and its condition check sees the published data.
//
// Chosen over condition variables because the notify side takes no mutex (a stage never blocks on
// another's lock), and over yield/sleep back-off because an idle stage then wakes at once instead
// of after its next poll. Linux-specific through platform/futex.h.
#include <atomic>
#include <cstdint>

#include "platform/futex.h"

namespace plumb::runtime {

class Doorbell {
 public:
  // Number of condition checks spent spinning before sleeping. Small: on 2 cores shared by
  // several stage threads a long spin steals the CPU from the thread that would make progress.
  static constexpr int kSpinChecks = 64;

  // Call after publishing whatever a waiter may be waiting for.
  void ring() {
    epoch_.fetch_add(1, std::memory_order_seq_cst);
    if (sleepers_.load(std::memory_order_seq_cst) != 0) futexWakeAll(&epoch_);
  }

  // Returns once ready() is true. ready() is called repeatedly and may have side effects only when
  // it returns true (e.g. a try_pop that succeeded).
  template <typename Ready>
  void waitUntil(Ready&& ready) {
    for (int i = 0; i < kSpinChecks; ++i) {
      if (ready()) return;
      cpuRelax();
    }
    for (;;) {
      sleepers_.fetch_add(1, std::memory_order_seq_cst);
      const uint32_t seen = epoch_.load(std::memory_order_seq_cst);
      if (ready()) {
        sleepers_.fetch_sub(1, std::memory_order_seq_cst);
        return;
      }
      futexWait(&epoch_, seen);
      sleepers_.fetch_sub(1, std::memory_order_seq_cst);
      if (ready()) return;
    }
  }

 private:
  static void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    asm volatile("yield");
#endif
  }

  std::atomic<uint32_t> epoch_{0};
  std::atomic<uint32_t> sleepers_{0};
};

}  // namespace plumb::runtime
