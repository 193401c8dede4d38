#pragma once
// OdometryStepper: push-style odometry for callers that own their frame loop (the public API,
// api/plumb/odometry.h). It runs THE stage objects of runOdometry() (pipeline/run/odometry_stages.h:
// ExtractStage, TrackStage, MapStage) over one OdometrySlot, lock-step, one frame per step(): the
// same calls in the same order as the deterministic mode of the runner, so the same frames give the
// same poses, byte for byte. No second implementation of anything: only the capture stage is
// replaced by the caller writing the frame into slot().image.
//
//   OdometryStepper stepper(system, sink);   // allocates the slot and the extractor, once
//   RgbdImage& image = stepper.slot().image;  // fill bgr / depth_raw / timestamp_s in place
//   stepper.step();                           // extract -> track (sink.onPose) -> map (sink.on*)
//   ...
//   stepper.finish();                         // every held-back pose reaches the sink
//
// After warm-up a step allocates nothing (as the runner's stages; tests/api checks it).
// Loop closing: with loop options the stepper owns a LoopStage in its synchronous (lock-step) form
// and hands it to the map stage exactly as the runner's deterministic mode does, so the stepper and
// `plumb run` give the same bytes with loop closing on as off.
#include <cstdint>
#include <memory>

#include "pipeline/odometry/mapper_fence.h"
#include "pipeline/run/odometry_run.h"
#include "pipeline/run/loop_stage.h"
#include "pipeline/run/odometry_stages.h"
#include "platform/status.h"

namespace plumb {

class OdometryStepper {
 public:
  // `system` and `sink` must outlive the stepper. Sets OpenCV to no worker threads, as the runner
  // does (process-wide): the stages are the parallelism and the output must not depend on a pool.
  // loop_options: nullptr = no loop closing; otherwise the loop stage runs lock-step.
  OdometryStepper(OdometrySystem& system, OdometrySink& sink, const loop::LoopCloserOptions* loop_options = nullptr);
  ~OdometryStepper();

  // The frame to fill before step(): write bgr (CV_8UC3, camera size), depth_raw (CV_16UC1, the
  // depth camera's size: camera.depthWidth() x depthHeight()) and timestamp_s; sequence and the
  // stamps are set by step(). Unregistered depth is registered by the runner's register stage.
  OdometrySlot& slot() { return slot_; }
  // One frame through extract, track and map. The tracked result is slot().tracked->output.
  Status step();
  // End of input: every pose held back for refinement and every keyframe reach the sink.
  Status finish();

  uint64_t frames() const { return frames_; }
  uint64_t extractionFailures() const { return extract_.failures() + register_.failures(); }

 private:
  OdometrySystem& system_;
  OdometrySink& sink_;
  OdometrySlot slot_;
  DropLog drops_;        // stays empty: nothing is dropped when the caller pushes frames
  MapperFence fence_{false};  // lock-step: never waits
  RegisterStage register_;
  ExtractStage extract_;
  TrackStage track_;
  std::unique_ptr<LoopStage> loop_;  // before map_, which is given it
  MapStage map_;
  uint64_t frames_ = 0;
  bool finished_ = false;
};

}  // namespace plumb
