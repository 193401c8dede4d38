#pragma once
// MapperFence: how the tracking side waits for the mapping side in a threaded run.
//
// Relocalizing reads the relocalizer, which the mapping thread writes. Before it, the tracking
// thread calls waitForMapper(), which returns once every frame tracked before the current one has
// been through the map stage: the mapping thread is then idle until the current frame reaches it,
// so the two threads never use the relocalizer at the same time. waitUntilMapped(n) waits for the
// first n frames only: the fixed lag of map updates waits there for the frame whose update is due
// (OdometrySystem::syncWithMapping), a frame that asked for a new map for that frame.
// waitUntilInserted(n) waits less: until frame n - 1's keyframe is inserted and its fresh map
// written (insertionPublished(), before that frame's local BA) or the frame is mapped, so the
// tracker can track the next frames while the map stage runs the BA (split map updates,
// SystemOptions::refine_lag_frames). In lock-step (`threaded` false) all of this is always already
// true and the fence never waits.
//
// It also carries how a run tracks against the map stage's updates, `max_frames_ahead`: 0 (the
// deterministic and fast schedules): at the fixed lag (SystemOptions::map_lag_frames), the same
// map in every schedule, so fast mode writes the deterministic bytes; > 0 (realtime): the newest
// snapshot, with at most that many frames tracked past a keyframe the tracker asked for before it
// waits for it. The runner chooses it per mode (pipeline/run/run_session.cpp, docs/RUNTIME.md
// "When the map stage falls behind").
#include <atomic>
#include <cstdint>

#include "runtime/doorbell.h"

namespace plumb {

class MapperFence {
 public:
  explicit MapperFence(bool threaded, int max_frames_ahead = 0)
      : threaded_(threaded), max_frames_ahead_(max_frames_ahead) {}

  bool threaded() const { return threaded_; }
  int maxFramesAhead() const { return max_frames_ahead_; }

  // Tracking thread: while frame number framesTracked() is being tracked.
  void waitForMapper() { (void)waitUntilMapped(frames_tracked_); }
  // Tracking thread: returns once the first `frames` frames have been through the map stage (or
  // it failed); true when that meant waiting.
  bool waitUntilMapped(uint64_t frames) {
    auto done = [this, frames] {
      return failed_.load(std::memory_order_acquire) || frames_mapped_.load(std::memory_order_acquire) >= frames;
    };
    if (!threaded_ || done()) return false;
    bell_.waitUntil(done);
    return true;
  }
  // Tracking thread: returns once the first `frames` - 1 frames have been through the map stage and
  // frame `frames` - 1 has published its fresh map (or has been mapped, or the map stage failed);
  // true when that meant waiting.
  bool waitUntilInserted(uint64_t frames) {
    auto done = [this, frames] {
      return failed_.load(std::memory_order_acquire) || frames_inserted_.load(std::memory_order_acquire) >= frames ||
             frames_mapped_.load(std::memory_order_acquire) >= frames;
    };
    if (!threaded_ || done()) return false;
    bell_.waitUntil(done);
    return true;
  }
  // Tracking thread: after each frame.
  void frameTracked() { ++frames_tracked_; }
  // Mapping thread, inside a frame: its keyframe's fresh map is written (the release publishes it).
  void insertionPublished() {
    frames_inserted_.store(frames_mapped_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
    bell_.ring();
  }
  // Mapping thread: after each frame, last (releases the mapper and relocalizer to a waiting
  // tracker). `failed`: the mapping side stopped, so nobody is left to wait for.
  void frameMapped(bool failed) {
    if (failed) failed_.store(true, std::memory_order_release);
    frames_mapped_.fetch_add(1, std::memory_order_release);
    bell_.ring();
  }

 private:
  const bool threaded_;
  const int max_frames_ahead_;
  uint64_t frames_tracked_ = 0;  // tracking thread only
  std::atomic<uint64_t> frames_mapped_{0};    // written by the mapping thread only
  std::atomic<uint64_t> frames_inserted_{0};  // insertionPublished(): frames_mapped_ + 1 then
  std::atomic<bool> failed_{false};
  runtime::Doorbell bell_;
};

}  // namespace plumb
