#pragma once
// Thin wrappers over the Linux futex system call: a thread sleeps in the kernel until another thread
// changes a 32-bit word and wakes it. The runtime's Doorbell builds its blocking wait on these, so a
// stage that has nothing to do costs no CPU and wakes within microseconds (no sleep-polling).
#include <atomic>
#include <cstdint>

namespace plumb {

// Sleeps while *word == expected, until futexWakeAll(word), a spurious wake-up, or timeout_ns
// elapses (timeout_ns < 0: no timeout). Returns immediately if *word != expected already; the
// comparison and the sleep are atomic in the kernel, which is what makes lost wake-ups impossible.
void futexWait(std::atomic<uint32_t>* word, uint32_t expected, int64_t timeout_ns = -1);

// Wakes every thread sleeping in futexWait on word.
void futexWakeAll(std::atomic<uint32_t>* word);

}  // namespace plumb
