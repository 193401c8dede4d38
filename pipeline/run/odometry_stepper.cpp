#include "pipeline/run/odometry_stepper.h"

#include <opencv2/core/utility.hpp>

namespace plumb {

OdometryStepper::OdometryStepper(OdometrySystem& system, OdometrySink& sink,
                                 const loop::LoopCloserOptions* loop_options)
    : system_(system),
      sink_(sink),
      register_(system.camera()),
      extract_(system),
      track_(system, fence_, sink),
      loop_(loop_options != nullptr ? std::make_unique<LoopStage>(system, *loop_options, false, 0) : nullptr),
      // Warm-up far away: the allocation bookkeeping is the runner's; callers measure themselves.
      map_(system, fence_, drops_, sink, UINT64_MAX, loop_.get()) {
  cv::setNumThreads(0);
  if (loop_) loop_->start();
  const PinholeCamera& camera = system.camera();
  slot_.image.bgr.create(camera.height, camera.width, CV_8UC3);
  slot_.image.depth_raw.create(camera.depthHeight(), camera.depthWidth(), CV_16UC1);
  if (register_.needed()) slot_.registered_depth.create(camera.height, camera.width, CV_16UC1);
  slot_.image.depth_factor = camera.depth_factor;
}

Status OdometryStepper::step() {
  if (finished_) return Status::Error("odometry stepper: step() after finish()");
  runtime::FrameStamps stamps;
  stamps.frame_index = frames_;
  stamps.t_recorded_ns = int64_t(slot_.image.timestamp_s * 1e9);
  slot_.image.sequence = frames_;
  slot_.dropped_before = 0;
  ++frames_;
  // The runner's lock-step order (runtime::StageRunner in deterministic mode).
  if (register_.needed()) PLUMB_RETURN_IF_ERROR(register_.process(slot_, stamps));
  PLUMB_RETURN_IF_ERROR(extract_.process(slot_, stamps));
  PLUMB_RETURN_IF_ERROR(track_.process(slot_, stamps));
  PLUMB_RETURN_IF_ERROR(map_.process(slot_, stamps));
  return Status::Ok();
}

OdometryStepper::~OdometryStepper() = default;

Status OdometryStepper::finish() {
  if (finished_) return Status::Ok();
  finished_ = true;
  map_.finish();
  Status status = map_.finishStatus();
  // The end of runOdometry(), in the same order: the loop stage's last correction reaches the map
  // before the final poses, retirements reach the closer, then its final optimisation.
  if (loop_) {
    loop_->finish();
    system_.applyLoopCorrection();
  }
  system_.finish(
      [&](const FinishedFrame& f) {
        if (status.ok()) status = sink_.onFinishedFrame(f);
      },
      [&](const RetiredKeyframe& kf) {
        if (loop_) loop_->keyframeRetired(kf, system_.stats().loop_corrections_applied);
        if (status.ok()) status = sink_.onRetiredKeyframe(kf);
      });
  if (loop_) loop_->finalOptimise();
  return status;
}

}  // namespace plumb
