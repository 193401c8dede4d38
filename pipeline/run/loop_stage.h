#pragma once
// LoopStage: loop closing on the one runner (docs/LOOP.md "The loop stage").
//
//   map stage, after a keyframe insertion:  keyframeInserted()
//       makes the LoopKeyframe record (pipeline/loop/loop_keyframe.h) from the request's features
//       and the mapper's poses, then
//     deterministic: runs LoopCloser::addKeyframe right there, in lock-step (byte-identical runs);
//     fast / realtime: pushes it into a bounded SPSC ring (kRingCapacity records) read by the loop
//       stage's own thread (nice 5 in realtime, like the map stage). A full ring DROPS the record
//       (counted): tracking and mapping never wait for loop closing.
//   an accepted loop -> LoopCloser's MapCorrection -> OdometrySystem::loopCorrections() (a
//       LatestSnapshot) -> the mapping side applies it before its next frame (mapFrame).
// finish() (end of run): the thread processes what is left in the ring and stops; then the graph's
// poses are final (optimisedPoses()).
// Memory: the LoopCloser (LoopCloser::memoryBytes), two records of scratch and the ring, all
// allocated in the constructor.
#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/loop/loop_closer.h"
#include "pipeline/odometry/odometry_system.h"
#include "runtime/doorbell.h"
#include "runtime/spsc_ring.h"

namespace plumb {

class LoopStage {
 public:
  static constexpr std::size_t kRingCapacity = 8;

  LoopStage(OdometrySystem& system, const loop::LoopCloserOptions& options, bool threaded, int thread_nice);
  ~LoopStage();
  LoopStage(const LoopStage&) = delete;
  LoopStage& operator=(const LoopStage&) = delete;

  void start();  // threaded: starts the thread
  // Map stage thread, for every frame whose output says a keyframe was inserted.
  void keyframeInserted(const TrackedFrame& tracked, const FrameOutput& output);
  // Processes what the ring still holds and joins the thread.
  void finish();

  // After finish():
  const loop::LoopStats& stats() const { return closer_->stats(); }
  uint64_t recordsDropped() const { return dropped_; }
  uint64_t correctionsPublished() const { return corrections_published_; }
  const loop::LoopCloser& closer() const { return *closer_; }

 private:
  void process(const loop::LoopKeyframe& record);
  void threadMain();

  OdometrySystem& system_;
  std::unique_ptr<loop::LoopCloser> closer_;
  const bool threaded_;
  const int thread_nice_;
  std::unique_ptr<loop::LoopKeyframe> made_;    // map stage thread
  std::unique_ptr<loop::LoopKeyframe> popped_;  // loop thread
  runtime::SpscRing<loop::LoopKeyframe> ring_;
  runtime::Doorbell doorbell_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  uint64_t dropped_ = 0;               // map stage thread
  uint64_t corrections_published_ = 0;  // loop thread
};

}  // namespace plumb
