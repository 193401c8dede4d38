#pragma once
// The stages of the odometry run (pipeline/run/odometry_run.h), each a runtime::Stage over one
// OdometrySlot. They hold no schedule of their own: runtime::StageRunner runs the same objects
// lock-step or threaded.
#include <atomic>
#include <cstdint>
#include <memory>

#include "pipeline/frontend/depth_registration.h"
#include "pipeline/frontend/feature_extractor.h"
#include "pipeline/odometry/mapper_fence.h"
#include "pipeline/odometry/odometry_system.h"
#include "runtime/spsc_ring.h"
#include "runtime/stage.h"
#include "sensor/frame_capture.h"

namespace plumb {

class OdometrySink;
class LoopStage;

// What one slot carries through the stages, allocated once with the pool. FrameFeatures and
// TrackedFrame are large (fixed capacities), so they live on the heap.
struct OdometrySlot {
  RgbdImage image;
  std::unique_ptr<FrameFeatures> features = std::make_unique<FrameFeatures>();
  std::unique_ptr<TrackedFrame> tracked = std::make_unique<TrackedFrame>();  // track -> map
  // Unregistered depth cameras only: image.depth_raw registered into the colour camera by the
  // register stage (sized once, with the pool), and whether this frame's is valid.
  cv::Mat registered_depth;
  bool depth_registered = false;
  double register_ms = 0;
  double extract_ms = 0;
  uint32_t dropped_before = 0;  // DropLog entries that precede this frame
};

// Frames the capture stage dropped (real-time: no free slot, or the source fell behind), on their
// way to the map stage, which gives each its place in the output trajectory: every slot says how
// many were dropped just before it; the rest are those after the last frame. Capacity: a stall of
// ~34 s at 30 Hz; beyond it a dropped frame gets no trajectory line (counted).
struct DroppedFrame {
  uint64_t sequence = 0;
  double timestamp_s = 0;
};
struct DropLog {
  static constexpr std::size_t kCapacity = 1024;
  runtime::SpscRing<DroppedFrame> ring{kCapacity};
  uint64_t not_logged = 0;  // capture thread only
  std::atomic<bool> input_ended{false};  // set by the capture stage when the input has ended
};

// Stage 0: a FrameCapture into slots; ends the input at max_frames or when `stop` is set.
class CaptureStage final : public runtime::Source<OdometrySlot> {
 public:
  CaptureStage(FrameCapture& capture, long max_frames, const std::atomic<bool>* stop, DropLog& drops)
      : capture_(capture), max_frames_(max_frames), stop_(stop), drops_(drops) {}
  bool peekNext(int64_t* t_recorded_ns) override;
  Status read(OdometrySlot& slot, const runtime::FrameStamps& stamps) override;
  void skip() override;
  bool stopRequested() override;
  bool stopped() const { return stopped_; }

 private:
  bool ended();

  FrameCapture& capture_;
  long max_frames_;
  const std::atomic<bool>* stop_;
  DropLog& drops_;
  long consumed_ = 0;
  uint32_t dropped_since_read_ = 0;
  bool stopped_ = false;
};

// Stage 1 when the camera's depth is not registered to colour (PinholeCamera::depth_camera; RunSession
// leaves it out otherwise): image.depth_raw, as the depth camera saw it, into the colour camera
// (pipeline/frontend/depth_registration.h), once per frame, into the slot's registered_depth.
class RegisterStage final : public runtime::Stage<OdometrySlot> {
 public:
  explicit RegisterStage(const PinholeCamera& camera) : registration_(camera) {}
  const char* name() const override { return "register"; }
  Status process(OdometrySlot& slot, const runtime::FrameStamps&) override;
  // Whether the camera needs it (a stage that would do nothing is not run at all).
  bool needed() const { return registration_.active(); }
  // Frames whose depth image did not fit the depth camera (their features are 2D-only).
  uint64_t failures() const { return failures_; }

 private:
  DepthRegistration registration_;
  uint64_t failures_ = 0;
};

// After the register stage, if any: its own FeatureExtractor (extractors are one per thread), the
// system's camera and options; reads the registered depth when there is a register stage. With
// stride 2 two of them follow each other in the chain, one extracting the even frames and passing
// the odd ones on, the other the reverse: the threaded modes extract two frames at once on two
// threads without fan-out (extraction is a function of the frame alone, so the features, and the
// bytes, are those of one extractor).
class ExtractStage final : public runtime::Stage<OdometrySlot> {
 public:
  explicit ExtractStage(const OdometrySystem& system, uint32_t stride = 1, uint32_t offset = 0);
  const char* name() const override;
  // Frames whose runner index is offset modulo stride; the others pass through untouched.
  Status process(OdometrySlot& slot, const runtime::FrameStamps& stamps) override;
  uint64_t failures() const { return failures_; }

 private:
  FeatureExtractor extractor_;
  uint32_t stride_, offset_;
  bool registered_depth_ = false;  // read slot.registered_depth (there is a register stage)
  uint64_t failures_ = 0;
};

// Stage 2: tracking and the keyframe decision; the keyframe request travels in the slot.
class TrackStage final : public runtime::Stage<OdometrySlot> {
 public:
  TrackStage(OdometrySystem& system, MapperFence& fence, OdometrySink& sink)
      : system_(system), fence_(fence), sink_(sink) {}
  const char* name() const override { return "track"; }
  Status process(OdometrySlot& slot, const runtime::FrameStamps&) override;

 private:
  OdometrySystem& system_;
  MapperFence& fence_;
  OdometrySink& sink_;
};

// Stage 3: local mapping for keyframe requests, the output trajectory, the sink.
class MapStage final : public runtime::Stage<OdometrySlot> {
 public:
  // loop may be nullptr (loop closing off); otherwise it hears of every inserted keyframe.
  MapStage(OdometrySystem& system, MapperFence& fence, DropLog& drops, OdometrySink& sink, uint64_t warmup_frames,
           LoopStage* loop = nullptr)
      : system_(system), fence_(fence), drops_(drops), sink_(sink), warmup_frames_(warmup_frames), loop_(loop) {}
  const char* name() const override { return "map"; }
  Status process(OdometrySlot& slot, const runtime::FrameStamps& stamps) override;
  // Frames dropped after the last processed one (the capture has finished).
  void finish() override;
  const Status& finishStatus() const { return finish_status_; }
  // The end of a run, after finish() and the loop stage's last correction: every frame held back
  // for refinement and then every keyframe reach the sink (and retired keyframes the loop stage).
  Status deliverTheRest();
  uint64_t frames() const { return frames_; }
  uint64_t framesDropped() const { return frames_dropped_; }
  uint64_t framesAfterWarmup() const { return frames_after_warmup_; }
  uint64_t allocationsAfterWarmup() const { return allocations_at_last_ - allocations_at_warmup_; }

 private:
  Status writeDrops(uint32_t count);
  Status deliver(const FrameOutput& out);
  // Finished frames, then retired keyframes, to the sink; a failure is kept in *status (the first
  // one), after which the sink hears of nothing more.
  void drain(bool end_of_run, Status* status);

  OdometrySystem& system_;
  MapperFence& fence_;
  DropLog& drops_;
  OdometrySink& sink_;
  uint64_t warmup_frames_;
  LoopStage* loop_;
  Status finish_status_;
  uint64_t frames_ = 0, frames_dropped_ = 0;
  uint64_t frames_after_warmup_ = 0;
  uint64_t allocations_at_warmup_ = 0;
  uint64_t allocations_at_last_ = 0;
};

}  // namespace plumb
