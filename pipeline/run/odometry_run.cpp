#include "pipeline/run/odometry_run.h"

#include <opencv2/core/utility.hpp>

#include "pipeline/run/odometry_stages.h"
#include "runtime/stage_runner.h"

namespace plumb {

Status validate(const OdometryRunOptions& options) {
  const runtime::RunOptions& s = options.schedule;
  if (s.slot_count < 1 || s.slot_count > 64) return Status::Error("slots must be within 1..64");
  if (s.realtime_priority < 0 || s.realtime_priority > 99) return Status::Error("realtime priority must be within 0..99");
  if (options.max_frames < -1 || options.max_frames == 0) {
    return Status::Error("max_frames must be a positive count (or -1: every frame)");
  }
  return Status::Ok();
}

Status runOdometry(FrameCapture& capture, OdometrySystem& system, OdometrySink& sink,
                   const OdometryRunOptions& options, OdometryRunResult* result) {
  PLUMB_RETURN_IF_ERROR(validate(options));
  runtime::RunOptions schedule = options.schedule;
  const bool lock_step = schedule.mode == runtime::RunMode::kDeterministic;
  // The simulation of real-time mode on a VirtualClock runs on one thread too: nobody else could
  // move the map stage on, so the fence must not wait.
  const bool simulated = schedule.mode == runtime::RunMode::kRealtime && schedule.clock != nullptr &&
                         schedule.clock->isVirtual();
  // Lock-step: each frame leaves the pipeline before the next is read, one slot is all it uses.
  if (lock_step) schedule.slot_count = 1;
  // The stages are the parallelism: OpenCV's own worker pool would compete with them for the
  // cores, and each fresh pool worker allocates thread-local state the first time it runs a
  // cv::parallel_for_ body, i.e. at unpredictable frames of a steady run.
  cv::setNumThreads(0);
  // Real time: mapping is off the latency path (poses are known when tracking is done), so under
  // contention the kernel serves capture, extract and track first. Nice 5, not more: the map stage
  // must still keep up on average, or the slots fill and frames drop. Not in fast mode, where every
  // stage is on the throughput path.
  if (schedule.mode == runtime::RunMode::kRealtime) {
    schedule.background_stages = 1u << 3;
    schedule.background_nice = 5;
  }
  // End to end = sensor time to pose known (track done); the map stage refines later frames' map.
  schedule.end_to_end_stage = 2;

  DropLog drops;
  MapperFence fence(!lock_step && !simulated);
  CaptureStage capture_stage(capture, options.max_frames, options.stop, drops);
  ExtractStage extract(system);
  TrackStage track(system, fence, sink);
  MapStage map(system, fence, drops, sink, options.warmup_frames);
  runtime::StageRunner<OdometrySlot> runner(capture_stage, {&extract, &track, &map}, schedule);
  Status status = runner.run();
  if (status.ok()) status = map.finishStatus();

  // Whatever ended the run, every pose computed so far (those held back for refinement too) and
  // every keyframe reach the sink.
  Status finish_status;
  system.finish(
      [&](const FinishedFrame& f) {
        if (finish_status.ok()) finish_status = sink.onFinishedFrame(f);
      },
      [&](const RetiredKeyframe& kf) {
        if (finish_status.ok()) finish_status = sink.onRetiredKeyframe(kf);
      });
  if (status.ok()) status = finish_status;

  result->report = runner.report();
  if (options.keep_trace) result->trace = runner.trace();
  result->frames = map.frames();
  result->frames_dropped = map.framesDropped();
  result->extraction_failures = extract.failures();
  result->drops_without_trajectory_line = drops.not_logged;
  result->stopped = capture_stage.stopped();
  const uint64_t counted = map.framesAfterWarmup();
  result->allocation_frames = counted > 0 ? counted - 1 : 0;
  result->allocations_after_warmup = map.allocationsAfterWarmup();
  return status;
}

}  // namespace plumb
