#pragma once
// Per-thread settings for pipeline stage threads: a name (shows in top -H, gdb, perf and the trace),
// pinning to one CPU, and real-time FIFO scheduling. Pinning and SCHED_FIFO usually need privileges
// (CAP_SYS_NICE or an rtprio limit); without them the calls fail with a Status and the thread keeps
// normal scheduling. applyThreadSettings() prints one warning per kind of failure per process, so
// six stage threads do not print six identical lines.
#include <string>

#include "platform/status.h"

namespace plumb {

struct ThreadSettings {
  std::string name;            // truncated to 15 characters (the kernel limit); empty: unchanged
  int cpu = -1;                // CPU to pin to; -1: no pinning
  int realtime_priority = 0;   // SCHED_FIFO priority 1..99; 0: normal (SCHED_OTHER) scheduling
};

Status setCurrentThreadName(const std::string& name);
Status pinCurrentThreadToCpu(int cpu);
// SCHED_FIFO at the given priority (1..99). Fails with a clear message when not permitted.
Status setCurrentThreadRealtimePriority(int priority);

// Applies every requested setting to the calling thread. Failures are warned about once per process
// on stderr and the thread falls back to what it had; the first failure is returned for callers
// that want to treat it as fatal.
Status applyThreadSettings(const ThreadSettings& settings);

// Number of CPUs this process may run on (its affinity mask), at least 1.
int availableCpuCount();

}  // namespace plumb
