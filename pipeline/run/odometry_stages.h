#pragma once
// The stages of the odometry run (pipeline/run/odometry_run.h), each a runtime::Stage over one
// OdometrySlot. They hold no schedule of their own: runtime::StageRunner runs the same objects
// lock-step or threaded.
#include <atomic>
#include <cstdint>
#include <memory>

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

// Stage 1: its own FeatureExtractor (extractors are one per thread), the system's camera and options.
class ExtractStage final : public runtime::Stage<OdometrySlot> {
 public:
  explicit ExtractStage(const OdometrySystem& system);
  const char* name() const override { return "extract"; }
  Status process(OdometrySlot& slot, const runtime::FrameStamps&) override;
  uint64_t failures() const { return failures_; }

 private:
  FeatureExtractor extractor_;
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
  uint64_t frames() const { return frames_; }
  uint64_t framesDropped() const { return frames_dropped_; }
  uint64_t framesAfterWarmup() const { return frames_after_warmup_; }
  uint64_t allocationsAfterWarmup() const { return allocations_at_last_ - allocations_at_warmup_; }

 private:
  Status writeDrops(uint32_t count);
  Status deliver(const FrameOutput& out);

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
