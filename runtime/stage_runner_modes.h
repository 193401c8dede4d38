#pragma once
// The three scheduling loops of StageRunner (included by stage_runner.h; not a public header).
#include "runtime/stage_runner.h"

namespace plumb::runtime {

template <typename T>
void StageRunner<T>::runLockStep() {
  while (!stop_requested_.load(std::memory_order_acquire)) {
    int64_t t_recorded_ns = 0;
    if (!source_.peekNext(&t_recorded_ns)) break;
    SlotIndex slot = 0;
    // The previous frame has left the pipeline, so a slot is always free.
    const bool acquired = pool_.tryAcquire(&slot);
    assert(acquired);
    (void)acquired;
    PipelineMessage m = capture(slot, next_frame_index_++, t_recorded_ns, -1);
    for (int s = 1; s <= lastStage(); ++s) m = step(s, m);
    complete(m);
    pool_.release(m.slot);
  }
  PipelineMessage end{Kind::kEndOfStream, 0};
  for (int s = 1; s <= lastStage(); ++s) end = step(s, end);
}

template <typename T>
void StageRunner<T>::applySettings(int s, const char* name) {
  ThreadSettings settings;
  settings.name = name;
  if (options_.pin_threads) settings.cpu = s % availableCpuCount();
  const bool background = s >= 1 && s < 32 && (options_.background_stages >> s & 1u) != 0;
  // With real-time priority P, a background stage runs SCHED_FIFO one level below the latency
  // path (P - 1): at normal priority it starved whenever other processes loaded the CPU (a soak on
  // a loaded machine: the map stage fell behind, tracking waited for it, p99 ~250 ms, hundreds of
  // drops), while one FIFO level below still yields to capture, extract and track.
  const int background_priority = options_.realtime_priority > 1 ? options_.realtime_priority - 1 : 0;
  settings.realtime_priority = background ? background_priority : options_.realtime_priority;
  (void)applyThreadSettings(settings);  // failures are warned about once and fall back
  if (background && settings.realtime_priority == 0) (void)setCurrentThreadNice(options_.background_nice);
}

template <typename T>
void StageRunner<T>::runThreaded() {
  std::vector<std::thread> threads;
  threads.reserve(stages_.size() + 1);
  for (int s = 1; s <= lastStage(); ++s) {
    threads.emplace_back([this, s] {
      applySettings(s, stages_[s - 1]->name());
      stageLoop(s);
    });
  }
  threads.emplace_back([this] {
    applySettings(0, source_.name());
    sourceLoop();
  });
  for (std::thread& thread : threads) thread.join();
}

template <typename T>
void StageRunner<T>::sourceLoop() {
  while (!stop_requested_.load(std::memory_order_acquire)) {
    int64_t t_recorded_ns = 0;
    if (!source_.peekNext(&t_recorded_ns)) break;
    const uint64_t frame_index = next_frame_index_++;
    int64_t t_sensor_ns = -1;
    SlotIndex slot = 0;
    if (realtime()) {
      t_sensor_ns = pacedTimeNs(t_recorded_ns);
      if (!sleepUntilOrStop(t_sensor_ns)) break;  // a stop during a long recorded gap
      if (skipIfLate(frame_index, t_sensor_ns, clock_.nowNs())) continue;
      if (!pool_.tryAcquire(&slot)) {  // every slot busy: drop, never wait
        source_.skip();
        recordDrop(frame_index, clock_.nowNs());
        continue;
      }
    } else {
      pool_.releasedBell().waitUntil([&] { return pool_.tryAcquire(&slot); });
    }
    send(1, capture(slot, frame_index, t_recorded_ns, t_sensor_ns));
  }
  send(1, {Kind::kEndOfStream, 0});
}

template <typename T>
void StageRunner<T>::stageLoop(int s) {
  Link& input = *links_[s];
  for (;;) {
    PipelineMessage m;
    input.bell.waitUntil([&] { return input.ring.try_pop(m); });
    const PipelineMessage out = step(s, m);
    send(s + 1, out);
    if (out.kind == Kind::kEndOfStream) return;
  }
}

template <typename T>
void StageRunner<T>::runSimulated() {
  auto& clock = static_cast<VirtualClock&>(clock_);
  const int last = lastStage();
  // Virtual time each message becomes available to its stage, parallel to the message rings.
  std::vector<std::unique_ptr<SpscRing<int64_t>>> ready_ns(last + 1);
  for (int s = 1; s <= last; ++s) ready_ns[s] = std::make_unique<SpscRing<int64_t>>(pool_.size() + 1);
  std::vector<int64_t> busy_until_ns(last + 1, clock.nowNs());  // [0] = source
  struct PendingRelease {
    SlotIndex slot;
    int64_t t_ns;
  };
  std::vector<PendingRelease> pending;  // slots done by the last stage, free from t_ns on
  pending.reserve(pool_.size());

  auto deliver = [&](int to, const PipelineMessage& m, int64_t t_ns) {
    if (to > last) {
      complete(m);
      if (m.carriesSlot()) pending.push_back({m.slot, t_ns});
      return;
    }
    const bool pushed = links_[to]->ring.try_push(m) && ready_ns[to]->try_push(t_ns);
    assert(pushed);
    (void)pushed;
  };
  auto releaseDueBy = [&](int64_t t_ns) {
    for (std::size_t i = 0; i < pending.size();) {
      if (pending[i].t_ns <= t_ns) {
        pool_.release(pending[i].slot);
        pending[i] = pending.back();
        pending.pop_back();
      } else {
        ++i;
      }
    }
  };

  bool source_open = true;
  for (;;) {
    // Earliest stage start; scanning from the last stage makes it win ties.
    int next_stage = 0;
    int64_t next_stage_t = std::numeric_limits<int64_t>::max();
    for (int s = last; s >= 1; --s) {
      const int64_t* ready = ready_ns[s]->front();
      if (ready == nullptr) continue;
      const int64_t t = std::max(*ready, busy_until_ns[s]);
      if (t < next_stage_t) {
        next_stage_t = t;
        next_stage = s;
      }
    }
    int64_t t_recorded_ns = 0;
    int64_t t_capture = 0;
    bool capture_next = false;
    if (source_open) {
      if (stop_requested_.load(std::memory_order_acquire) || !source_.peekNext(&t_recorded_ns)) {
        source_open = false;
        deliver(1, {Kind::kEndOfStream, 0}, busy_until_ns[0]);
        continue;
      }
      t_capture = std::max(pacedTimeNs(t_recorded_ns), busy_until_ns[0]);
      capture_next = t_capture < next_stage_t;
    }
    if (!capture_next && next_stage == 0) break;  // nothing left anywhere

    if (capture_next) {
      releaseDueBy(t_capture);
      clock.setNs(t_capture);
      const uint64_t frame_index = next_frame_index_++;
      if (skipIfLate(frame_index, pacedTimeNs(t_recorded_ns), t_capture)) continue;
      SlotIndex slot = 0;
      if (!pool_.tryAcquire(&slot)) {
        source_.skip();
        recordDrop(frame_index, t_capture);
        continue;
      }
      const PipelineMessage m = capture(slot, frame_index, t_recorded_ns, pacedTimeNs(t_recorded_ns));
      busy_until_ns[0] = clock.nowNs();
      deliver(1, m, busy_until_ns[0]);
    } else {
      PipelineMessage m;
      int64_t ready = 0;
      const bool popped = links_[next_stage]->ring.try_pop(m) && ready_ns[next_stage]->try_pop(ready);
      assert(popped);
      (void)popped;
      clock.setNs(next_stage_t);
      const PipelineMessage out = step(next_stage, m);
      busy_until_ns[next_stage] = clock.nowNs();
      deliver(next_stage + 1, out, busy_until_ns[next_stage]);
    }
  }
  releaseDueBy(std::numeric_limits<int64_t>::max());
  clock.setNs(*std::max_element(busy_until_ns.begin(), busy_until_ns.end()));
}

template <typename T>
Status StageRunner<T>::finishReport() {
  report_.mode = runModeName(options_.mode);
  report_.stages.clear();
  for (int s = 0; s <= lastStage(); ++s) {
    report_.stages.push_back({tracks_[s].name(), state_[s].latency});
  }
  report_.end_to_end_stage = endToEndStage();
  report_.wall_ns = report_.frames_completed > 0 ? t_last_done_ns_ - t_first_start_ns_ : 0;
  for (int s = 0; s <= lastStage(); ++s) {
    if (!state_[s].error.ok()) return state_[s].error.withContext("stage " + tracks_[s].name());
  }
  return Status::Ok();
}

}  // namespace plumb::runtime
