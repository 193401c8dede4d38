#include "viewer/run_feed.h"

namespace plumb::viewer {

void RunFeed::recordLatency(uint64_t sequence, int64_t latency_ns) {
  LatencySlot& slot = latency_[sequence % kLatencySlots];
  slot.latency_ns.store(latency_ns, std::memory_order_relaxed);
  slot.sequence.store(sequence, std::memory_order_release);
}

void RunFeed::pushFrame(const FeedFrame& frame) {
  FeedFrame out = frame;
  // The frame reached the map stage after the track stage's onPose for it, through the runner's
  // rings (release/acquire), so its entry is there unless 128 newer frames overwrote it.
  const LatencySlot& slot = latency_[frame.sequence % kLatencySlots];
  if (slot.sequence.load(std::memory_order_acquire) == frame.sequence) {
    out.latency_ms = double(slot.latency_ns.load(std::memory_order_relaxed)) * 1e-6;
  }
  if (!frames_.try_push(out)) records_dropped_.fetch_add(1, std::memory_order_relaxed);
}

void RunFeed::pushFinishedPose(const FeedFinishedPose& pose) {
  if (!finished_.try_push(pose)) records_dropped_.fetch_add(1, std::memory_order_relaxed);
}

void RunFeed::pushLoop(const FeedLoop& loop) {
  if (!loops_.try_push(loop)) records_dropped_.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace plumb::viewer
