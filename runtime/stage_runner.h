#pragma once
// StageRunner<T>: runs a Source<T> and a chain of Stage<T>s over a SlotPool, in one of three modes
// (run_options.h). The stages are the same objects in every mode; only the scheduling differs.
//
//   threaded (fast, realtime): one thread per stage plus one for the source. Stages pass
//     PipelineMessages (slot indices) through SpscRings; an idle stage sleeps on its input ring's
//     Doorbell (brief spin, then futex), so no thread polls.
//   lock-step (deterministic): the calling thread takes each frame through every stage before
//     reading the next, so stage state (e.g. the map tracking sees) evolves exactly as in a
//     single-threaded program, independent of timing.
//   simulated (realtime on a VirtualClock): one thread replays what the threaded pipeline would do,
//     event by event in virtual-time order. Each stage is busy from the virtual time it starts a
//     frame until its process() has advanced the clock; a frame is captured at its paced time if
//     a slot is free then, else dropped. Ties go to the later stage (a slot released at t is free
//     for a frame captured at t). This makes pacing and dropping exactly testable.
//
// End of stream and errors are messages (pipeline_message.h): they arrive behind the frames that
// preceded them. After a stage fails, later slots pass through to the last stage, which returns
// them to the pool, and the source stops; run() returns the error with the stage's name.
//
// Everything is allocated in the constructor and at the start of run(): slots, rings, trace
// buffers, histograms. A steady-state frame allocates nothing in the runtime.
#include <algorithm>
#include <atomic>
#include <cassert>
#include <cstdint>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "platform/memory_lock.h"
#include "platform/status.h"
#include "platform/thread_control.h"
#include "runtime/clock.h"
#include "runtime/doorbell.h"
#include "runtime/frame_stamps.h"
#include "runtime/latency_histogram.h"
#include "runtime/pipeline_message.h"
#include "runtime/run_options.h"
#include "runtime/run_report.h"
#include "runtime/slot_pool.h"
#include "runtime/spsc_ring.h"
#include "runtime/stage.h"
#include "runtime/thread_nice.h"
#include "runtime/trace_log.h"

namespace plumb::runtime {

// What the pool holds: the runtime's timing beside the application's payload.
template <typename T>
struct PipelineSlot {
  FrameStamps stamps;
  T payload{};
};

template <typename T>
class StageRunner {
 public:
  using Slot = PipelineSlot<T>;
  using Kind = PipelineMessage::Kind;

  // stages: processing order; at most kMaxStages - 1 (checked by run()). Pointers must outlive
  // the runner.
  StageRunner(Source<T>& source, std::vector<Stage<T>*> stages, const RunOptions& options)
      : source_(source),
        stages_(std::move(stages)),
        options_(options),
        clock_(options.clock != nullptr ? *options.clock : monotonicClock()),
        pool_(std::max<std::size_t>(1, options.slot_count)),
        state_(stages_.size() + 1) {
    // Each ring holds at most every slot plus the end-of-stream message, so a push never fails.
    links_.resize(stages_.size() + 1);
    for (std::size_t s = 1; s <= stages_.size(); ++s) {
      links_[s] = std::make_unique<Link>(pool_.size() + 1);
    }
    tracks_.reserve(stages_.size() + 1);
    tracks_.emplace_back(source_.name(), options.trace_capacity_per_stage);
    for (Stage<T>* stage : stages_) tracks_.emplace_back(stage->name(), options.trace_capacity_per_stage);
  }

  StageRunner(const StageRunner&) = delete;
  StageRunner& operator=(const StageRunner&) = delete;

  // Runs the source to its end (or to the first error). Call once. Returns the first failing
  // stage's error (in pipeline order), prefixed with its name.
  Status run() {
    if (stages_.size() + 1 > static_cast<std::size_t>(kMaxStages)) {
      return Status::Error("pipeline has " + std::to_string(stages_.size()) +
                           " stages; at most " + std::to_string(kMaxStages - 1) + " supported");
    }
    if (options_.lock_memory) lockProcessMemoryOrWarn();
    switch (options_.mode) {
      case RunMode::kDeterministic: runLockStep(); break;
      case RunMode::kFast: runThreaded(); break;
      case RunMode::kRealtime:
        if (clock_.isVirtual()) {
          runSimulated();
        } else {
          runThreaded();
        }
        break;
    }
    return finishReport();
  }

  const RunReport& report() const { return report_; }
  // One track per stage, [0] = source; read after run().
  const std::vector<TraceTrack>& trace() const { return tracks_; }
  SlotPool<Slot>& pool() { return pool_; }
  int stageCount() const { return static_cast<int>(stages_.size()); }

 private:
  struct Link {
    explicit Link(std::size_t capacity) : ring(capacity) {}
    SpscRing<PipelineMessage> ring;
    Doorbell bell;  // rung after every push
  };
  // Written only by the thread running that stage; read after the threads have joined.
  struct StageState {
    LatencyHistogram latency;
    Status error;
    bool failed = false;
  };

  bool realtime() const { return options_.mode == RunMode::kRealtime; }
  int lastStage() const { return stageCount(); }
  int endToEndStage() const {
    const int s = options_.end_to_end_stage;
    return s >= 1 && s <= lastStage() ? s : lastStage();
  }

  // Recording time -> run-clock time: the first frame is due now, the others keep their spacing.
  // Real-time pacing's wait: until t_ns, or false as soon as the source reports a stop request
  // (checked every kStopPollNs: a SIGINT during a long recorded gap ends the run at once).
  static constexpr int64_t kStopPollNs = 50'000'000;
  bool sleepUntilOrStop(int64_t t_ns) {
    if (clock_.isVirtual()) {
      clock_.sleepUntilNs(t_ns);
      return true;
    }
    for (;;) {
      if (source_.stopRequested()) return false;
      const int64_t now = clock_.nowNs();
      if (now >= t_ns) return true;
      clock_.sleepUntilNs(std::min(t_ns, now + kStopPollNs));
    }
  }

  int64_t pacedTimeNs(int64_t t_recorded_ns) {
    if (!have_pacing_origin_) {
      have_pacing_origin_ = true;
      t_recorded_origin_ns_ = t_recorded_ns;
      t_clock_origin_ns_ = clock_.nowNs();
    }
    return t_clock_origin_ns_ + (t_recorded_ns - t_recorded_origin_ns_);
  }

  // Stage 0: reads the next frame into slot. t_sensor_ns < 0: the frame exists from now on.
  PipelineMessage capture(SlotIndex slot_index, uint64_t frame_index, int64_t t_recorded_ns,
                          int64_t t_sensor_ns) {
    Slot& slot = pool_[slot_index];
    FrameStamps& stamps = slot.stamps;
    stamps = FrameStamps{};
    stamps.frame_index = frame_index;
    stamps.t_recorded_ns = t_recorded_ns;
    stamps.t_start_ns[0] = clock_.nowNs();
    stamps.t_sensor_ns = t_sensor_ns < 0 ? stamps.t_start_ns[0] : t_sensor_ns;
    if (report_.frames_read == 0) t_first_start_ns_ = stamps.t_start_ns[0];
    Status status = source_.read(slot.payload, stamps);
    stamps.t_done_ns[0] = clock_.nowNs();
    ++report_.frames_read;
    tracks_[0].add({TraceRecord::Kind::kSpan, frame_index, stamps.t_sensor_ns,
                    stamps.t_start_ns[0], stamps.t_done_ns[0]});
    if (!status.ok()) return fail(0, std::move(status), slot_index);
    state_[0].latency.add(stamps.t_done_ns[0] - stamps.t_start_ns[0]);
    return {Kind::kFrame, slot_index};
  }

  // Stage s >= 1 handles one message and returns the one to pass on.
  PipelineMessage step(int s, PipelineMessage in) {
    StageState& state = state_[s];
    switch (in.kind) {
      case Kind::kEndOfStream:
        if (!state.failed) stages_[s - 1]->finish();
        return in;
      case Kind::kPassThrough:
        return in;
      case Kind::kError:  // upstream failed: this stage stops too
        state.failed = true;
        return in;
      case Kind::kFrame:
        break;
    }
    if (state.failed) return {Kind::kPassThrough, in.slot};
    Slot& slot = pool_[in.slot];
    const int64_t t_start = clock_.nowNs();
    Status status = stages_[s - 1]->process(slot.payload, slot.stamps);
    const int64_t t_done = clock_.nowNs();
    slot.stamps.t_start_ns[s] = t_start;
    slot.stamps.t_done_ns[s] = t_done;
    tracks_[s].add({TraceRecord::Kind::kSpan, slot.stamps.frame_index, slot.stamps.t_sensor_ns,
                    t_start, t_done});
    if (!status.ok()) return fail(s, std::move(status), in.slot);
    state.latency.add(t_done - t_start);
    return in;
  }

  PipelineMessage fail(int s, Status status, SlotIndex slot_index) {
    state_[s].error = std::move(status);
    state_[s].failed = true;
    stop_requested_.store(true, std::memory_order_release);
    return {Kind::kError, slot_index};
  }

  // Bookkeeping for a message leaving the last stage (the slot is released separately).
  void complete(const PipelineMessage& m) {
    if (m.kind != Kind::kFrame) return;
    const FrameStamps& stamps = pool_[m.slot].stamps;
    const int64_t t_done = stamps.t_done_ns[lastStage()];
    report_.end_to_end.add(stamps.t_done_ns[endToEndStage()] - stamps.t_sensor_ns);
    ++report_.frames_completed;
    t_last_done_ns_ = std::max(t_last_done_ns_, t_done);
  }

  void recordDrop(uint64_t frame_index, int64_t t_ns) {
    ++report_.frames_dropped;
    tracks_[0].add({TraceRecord::Kind::kDrop, frame_index, t_ns, t_ns, t_ns});
  }

  // Real-time replay: a frame whose capture would start more than max_source_lag_ns after its due
  // time is skipped. Without this a source that cannot keep up (slow decoding) falls further
  // behind every frame and the end-to-end latency grows without bound; a live sensor never
  // delivers stale frames, its newer frame replaces the old one.
  bool skipIfLate(uint64_t frame_index, int64_t t_due_ns, int64_t t_now_ns) {
    if (options_.max_source_lag_ns <= 0 || t_now_ns - t_due_ns <= options_.max_source_lag_ns) return false;
    source_.skip();
    ++report_.frames_late;
    tracks_[0].add({TraceRecord::Kind::kLate, frame_index, t_due_ns, t_now_ns, t_now_ns});
    return true;
  }

  // Threaded hand-off to stage `to` (lastStage() + 1: out of the pipeline).
  void send(int to, const PipelineMessage& m) {
    if (to > lastStage()) {
      complete(m);
      if (m.carriesSlot()) pool_.release(m.slot);
      return;
    }
    Link& link = *links_[to];
    // Unreachable by construction (ring capacity > slots in flight); yield rather than corrupt.
    while (!link.ring.try_push(m)) std::this_thread::yield();
    link.bell.ring();
  }

  void runLockStep();
  void runThreaded();
  void runSimulated();
  void sourceLoop();
  void stageLoop(int s);
  void applySettings(int s, const char* name);
  Status finishReport();

  Source<T>& source_;
  std::vector<Stage<T>*> stages_;
  RunOptions options_;
  Clock& clock_;
  SlotPool<Slot> pool_;
  std::vector<std::unique_ptr<Link>> links_;  // links_[s] feeds stage s; [0] unused
  std::vector<StageState> state_;              // [0] = source
  std::vector<TraceTrack> tracks_;             // [0] = source
  RunReport report_;
  std::atomic<bool> stop_requested_{false};

  // Source-thread state.
  bool have_pacing_origin_ = false;
  int64_t t_recorded_origin_ns_ = 0;
  int64_t t_clock_origin_ns_ = 0;
  uint64_t next_frame_index_ = 0;
  int64_t t_first_start_ns_ = 0;
  // Last-stage-thread state.
  int64_t t_last_done_ns_ = 0;
};

}  // namespace plumb::runtime

#include "runtime/stage_runner_modes.h"
