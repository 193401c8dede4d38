#pragma once
// How a pipeline run is executed. Filled by tools/ from the command line; the runtime reads no
// files or environment.
#include <cstddef>
#include <cstdint>
#include <string>

#include "platform/status.h"

namespace plumb::runtime {

class Clock;

enum class RunMode {
  // One thread per stage; the source is paced to the recorded timestamps and a frame that finds
  // no free slot is dropped and counted. On a VirtualClock the same rules are simulated on one
  // thread, event by event, so drops are reproducible.
  kRealtime,
  // One thread per stage; the source reads as fast as slots come back. No frame is dropped.
  kFast,
  // Every stage in lock-step on the calling thread, one frame at a time through all stages:
  // each frame sees exactly the state (e.g. the map) the single-threaded program would see.
  kDeterministic,
};

const char* runModeName(RunMode mode);
Status parseRunMode(const std::string& text, RunMode* mode);

struct RunOptions {
  RunMode mode = RunMode::kFast;
  // Frame slots in flight. More slots absorb longer stalls in real-time mode at the cost of
  // latency and memory; 4 = one per stage of capture -> extract -> track -> map.
  std::size_t slot_count = 4;
  // nullptr: the real monotonic clock.
  Clock* clock = nullptr;
  // Real-time mode: frames the source reaches more than this long after their due time are
  // skipped and counted as late (the replay fell behind); <= 0: never skip.
  int64_t max_source_lag_ns = 50'000'000;
  // Processing stage (1..N) whose completion ends a frame's end-to-end latency (t_done - t_sensor);
  // 0 = the last stage. For plumb: tracking, when the pose is known; mapping only refines the map
  // later frames are tracked against.
  int end_to_end_stage = 0;
  // Trace records kept per stage (preallocated); later frames are counted, not recorded.
  std::size_t trace_capacity_per_stage = 8192;
  // Stage threads: SCHED_FIFO priority (0 = normal scheduling) and pinning to CPU (i % cores).
  // Both fall back, with one warning, when not permitted.
  int realtime_priority = 0;
  bool pin_threads = false;
  // Stages (bit s = processing stage s, 1..N) whose results are off the latency path (plumb: map)
  // run at nice background_nice (threaded modes), so that under CPU contention the kernel gives the
  // latency-path stages the core first; they still get the idle time. Lowering one's own priority
  // needs no privilege. With realtime_priority P > 1 they run SCHED_FIFO at P - 1 instead (below
  // the latency path, above every normal process).
  uint32_t background_stages = 0;
  int background_nice = 10;
  // mlockall before the run (falls back with one warning).
  bool lock_memory = false;
};

}  // namespace plumb::runtime
