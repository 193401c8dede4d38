#include "pipeline/run/odometry_stages.h"

#include <chrono>

#include "pipeline/run/loop_stage.h"
#include "pipeline/run/odometry_run.h"
#include "platform/allocation_counter.h"

namespace plumb {

// ---------------------------------------------------------------------------------------------
// CaptureStage

bool CaptureStage::ended() {
  drops_.input_ended.store(true);
  return false;
}

bool CaptureStage::peekNext(int64_t* t_recorded_ns) {
  if (max_frames_ >= 0 && consumed_ >= max_frames_) return ended();
  if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) {
    stopped_ = true;
    return ended();
  }
  if (capture_.prepareNext(t_recorded_ns)) return true;
  // A live source without frames ends the capture when the stop flag is set: that is a stop too.
  if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) stopped_ = true;
  return ended();
}

bool CaptureStage::stopRequested() {
  if (stopped_ || stop_ == nullptr || !stop_->load(std::memory_order_relaxed)) return stopped_;
  stopped_ = true;
  ended();  // the runner reads no more: the input has ended here, as in peekNext
  return true;
}

Status CaptureStage::read(OdometrySlot& slot, const runtime::FrameStamps& stamps) {
  ++consumed_;
  PLUMB_RETURN_IF_ERROR(capture_.take(slot.image));
  slot.image.t_sensor_ns = stamps.t_sensor_ns;
  slot.dropped_before = dropped_since_read_;
  dropped_since_read_ = 0;
  return Status::Ok();
}

void CaptureStage::skip() {
  ++consumed_;
  DroppedFrame dropped;
  if (!capture_.drop(&dropped.sequence, &dropped.timestamp_s)) return;
  if (drops_.ring.try_push(dropped)) {
    ++dropped_since_read_;
  } else {
    ++drops_.not_logged;
  }
}

// ---------------------------------------------------------------------------------------------
// RegisterStage, ExtractStage, TrackStage

Status RegisterStage::process(OdometrySlot& slot, const runtime::FrameStamps&) {
  const auto start = std::chrono::steady_clock::now();
  slot.depth_registered =
      registration_.registerInto(slot.image.depth_raw, slot.image.depth_factor, slot.registered_depth);
  // A depth image that does not fit the depth camera is not guessed at: the frame goes on without
  // depth (2D-only features), counted.
  if (!slot.depth_registered) ++failures_;
  slot.register_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

ExtractStage::ExtractStage(const OdometrySystem& system, uint32_t stride, uint32_t offset)
    : extractor_(system.camera(), system.options().odometry.extractor),
      stride_(stride),
      offset_(offset),
      registered_depth_(!system.camera().depthRegistered()) {}

const char* ExtractStage::name() const {
  if (stride_ == 1) return "extract";
  return offset_ == 0 ? "extract-even" : "extract-odd";
}

Status ExtractStage::process(OdometrySlot& slot, const runtime::FrameStamps& stamps) {
  if (stamps.frame_index % stride_ != offset_) return Status::Ok();
  const auto start = std::chrono::steady_clock::now();
  // Unregistered depth is never read as it came: registered, or none at all.
  static const cv::Mat kNoDepth;
  const cv::Mat& depth = !registered_depth_ ? slot.image.depth_raw
                         : slot.depth_registered ? slot.registered_depth
                                                 : kNoDepth;
  // A frame that does not fit the camera is tracked featureless (and counted): it keeps its place.
  if (!extractor_.extract(slot.image.bgr, depth, slot.image.depth_factor, *slot.features)) {
    slot.features->clear();
    ++failures_;
  }
  slot.extract_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

Status TrackStage::process(OdometrySlot& slot, const runtime::FrameStamps&) {
  system_.trackFeatures(*slot.features, slot.image.sequence, slot.image.timestamp_s, &fence_, slot.tracked.get());
  slot.tracked->output.extract_ms = slot.extract_ms;
  slot.tracked->output.register_ms = slot.register_ms;
  slot.tracked->output.t_sensor_ns = slot.image.t_sensor_ns;
  fence_.frameTracked();
  sink_.onPose(slot.tracked->output);
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------------
// MapStage

void MapStage::drain(bool end_of_run, Status* status) {
  system_.drainFinishedFrames(
      [&](const FinishedFrame& f) {
        if (status->ok()) *status = sink_.onFinishedFrame(f);
      },
      end_of_run);
  if (end_of_run) system_.retireAllKeyframes();
  system_.drainRetiredKeyframes([&](const RetiredKeyframe& kf) {
    if (loop_ != nullptr) loop_->keyframeRetired(kf, system_.stats().loop_corrections_applied);
    if (status->ok()) *status = sink_.onRetiredKeyframe(kf);
  });
}

Status MapStage::deliver(const FrameOutput& out) {
  Status status = sink_.onFrame(out);
  drain(false, &status);
  return status;
}

Status MapStage::deliverTheRest() {
  Status status;
  drain(true, &status);
  return status;
}

Status MapStage::writeDrops(uint32_t count) {
  Status status;
  DroppedFrame dropped;
  for (uint32_t i = 0; i < count && drops_.ring.try_pop(dropped); ++i) {
    ++frames_dropped_;
    const Status s = deliver(system_.mapDroppedFrame(dropped.sequence, dropped.timestamp_s));
    if (status.ok()) status = s;
  }
  return status;
}

Status MapStage::process(OdometrySlot& slot, const runtime::FrameStamps& stamps) {
  Status status = writeDrops(slot.dropped_before);
  ++frames_;
  const FrameOutput& out = system_.mapFrame(*slot.tracked, &fence_);
  // Before the fence releases the mapper: the record reads the mapper's poses.
  if (loop_ != nullptr) loop_->keyframeInserted(*slot.tracked, out);
  const Status s = deliver(out);
  if (status.ok()) status = s;
  // A loop closed in lock-step corrects the map before the next frame is tracked (a threaded loop
  // stage's correction waits for the next mapFrame instead). After deliver(): the keyframes this
  // frame retired carry poses from before the correction, so they go to the closer with the epoch
  // of before it.
  if (loop_ != nullptr && loop_->synchronous()) system_.applyLoopCorrection();
  sink_.onFrameView(FrameView{out, slot.image, system_.mapper().localMap(), system_.stats(),
                              system_.lastLoopCorrection()});
  // Process-wide count, read on this thread after each frame: from the first frame at or after
  // warm-up to the last one finished before the input ended, every thread's allocations are
  // included. The count is read before the flag, so a reading taken after a stage thread began
  // to exit is never kept.
  if (stamps.frame_index >= warmup_frames_) {
    const uint64_t now = allocationCount();
    if (!drops_.input_ended.load()) {
      if (frames_after_warmup_ == 0) allocations_at_warmup_ = now;
      allocations_at_last_ = now;
      ++frames_after_warmup_;
    }
  }
  // Last: the mapper and relocalizer are released to a waiting track stage.
  fence_.frameMapped(!status.ok());
  return status;
}

void MapStage::finish() {
  const Status status = writeDrops(UINT32_MAX);
  if (finish_status_.ok()) finish_status_ = status;
}

}  // namespace plumb
