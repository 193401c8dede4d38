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
// Memory: the LoopCloser (LoopCloser::memoryBytes), one record of scratch (two when threaded) and
// the rings, all allocated in the constructor (the rings' cells are written only when threaded).
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

  // Before start(): the loaded map's keyframes, graph and loop edges (LoopCloser::restoreMap).
  Status restoreMap(const loop::SavedMap& map) { return closer_->restoreMap(map); }
  void start();  // threaded: starts the thread
  // Map stage thread, for every frame whose output says a keyframe was inserted.
  void keyframeInserted(const TrackedFrame& tracked, const FrameOutput& output);
  // Map stage thread: a keyframe left the local map with its final pose (OdometrySystem's retired
  // keyframes); `epoch` = loop corrections applied so far. Through a second small ring (full:
  // dropped, counted) in the threaded modes. See LoopCloser::keyframeFinal.
  void keyframeRetired(const RetiredKeyframe& keyframe, uint64_t epoch);
  // Processes what the rings still hold and joins the thread. After it the stage is synchronous:
  // keyframeRetired() goes straight to the closer (the end of run's retirements).
  void finish();
  // After finish() and the last retirements: the final optimisation (LoopCloser::finalOptimise).
  void finalOptimise() { closer_->finalOptimise(); }

  // Records are processed on the caller's thread (lock-step and fast mode, and after finish()).
  bool synchronous() const { return synchronous_; }

  // After finish():
  const loop::LoopStats& stats() const { return closer_->stats(); }
  uint64_t recordsDropped() const { return dropped_; }
  uint64_t correctionsPublished() const { return corrections_published_; }
  const loop::LoopCloser& closer() const { return *closer_; }

 private:
  struct FinalPose {
    uint32_t id = 0;
    uint64_t epoch = 0;
    bool covariance_valid = false;
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
    Matrix6d covariance = Matrix6d::Zero();
  };
  static constexpr std::size_t kFinalRingCapacity = 64;
  // Reserved loop-closer memory made resident per keyframe (~0.3-0.5 ms of page faults where
  // fresh memory costs ~0.4 ms/MiB; loop thread in the threaded modes).
  static constexpr std::size_t kResidentBytesPerKeyframe = std::size_t(1) << 20;
  void process(const loop::LoopKeyframe& record);
  void processFinal(const FinalPose& f);
  bool popAndProcess();  // loop thread: one item of either ring; false when both are empty
  void threadMain();

  OdometrySystem& system_;
  std::unique_ptr<loop::LoopCloser> closer_;
  const bool threaded_;
  const int thread_nice_;
  std::unique_ptr<loop::LoopKeyframe> made_;    // map stage thread
  std::unique_ptr<loop::LoopKeyframe> popped_;  // loop thread (threaded modes only)
  runtime::SpscRing<loop::LoopKeyframe> ring_;
  runtime::SpscRing<FinalPose> final_ring_;
  bool synchronous_;  // deterministic mode, or after finish()
  runtime::Doorbell doorbell_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  uint64_t dropped_ = 0;                // map stage thread (records and final poses)
  uint64_t keyframes_processed_ = 0;    // by process(): the thread that runs it
  uint64_t corrections_published_ = 0;  // loop thread
};

}  // namespace plumb
