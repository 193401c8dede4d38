#include "pipeline/run/loop_stage.h"

#include "runtime/thread_nice.h"

namespace plumb {

namespace {

loop::LoopCloserOptions withSystemNoise(const loop::LoopCloserOptions& options,
                                        const OdometrySystem& system) {
  loop::LoopCloserOptions o = options;
  o.verifier.use_lines = o.verifier.use_lines && system.options().odometry.tracker.use_lines;
  // The loop constraint's covariance is calibrated like the odometry's (docs/UNCERTAINTY.md).
  o.verifier.uncertainty = system.options().odometry.uncertainty;
  o.verifier.rolling_shutter_readout_s = system.camera().rolling_shutter_readout_s;
  return o;
}

CameraIntrinsics intrinsicsOf(const PinholeCamera& c) {
  return CameraIntrinsics{c.fx, c.fy, c.cx, c.cy, c.fx * c.baseline_m};
}

}  // namespace

LoopStage::LoopStage(OdometrySystem& system, const loop::LoopCloserOptions& options, bool threaded,
                     int thread_nice)
    : system_(system),
      closer_(std::make_unique<loop::LoopCloser>(intrinsicsOf(system.camera()),
                                                 system.options().odometry.extractor.noise,
                                                 withSystemNoise(options, system))),
      threaded_(threaded),
      thread_nice_(thread_nice),
      made_(std::make_unique<loop::LoopKeyframe>()),
      popped_(threaded ? std::make_unique<loop::LoopKeyframe>() : nullptr),  // only the thread pops
      ring_(kRingCapacity),
      final_ring_(kFinalRingCapacity),
      synchronous_(!threaded) {}

LoopStage::~LoopStage() { finish(); }

void LoopStage::start() {
  if (threaded_ && !thread_.joinable()) thread_ = std::thread([this] { threadMain(); });
}

void LoopStage::keyframeInserted(const TrackedFrame& tracked, const FrameOutput& output) {
  if (!output.keyframe || !output.insert.inserted) return;
  if (!loop::makeLoopKeyframe(tracked.request, output.insert.keyframe_id, output.new_map, system_.mapper(),
                              made_.get())) {
    return;
  }
  if (synchronous_) {
    process(*made_);
    return;
  }
  if (!ring_.try_push(*made_)) {
    ++dropped_;
    return;
  }
  doorbell_.ring();
}

void LoopStage::process(const loop::LoopKeyframe& record) {
  const bool corrected = closer_->addKeyframe(record);
  // The closer's reserved stores become resident a slice per keyframe from the second keyframe
  // on: the first is the first frame, whose pose must not wait for ~8 MiB of page faults
  // (loop_closer.h MEMORY). After ~8 keyframes it is all resident and RSS stays flat.
  if (keyframes_processed_++ > 0) closer_->makeResidentStep(kResidentBytesPerKeyframe);
  if (!corrected) return;
  runtime::LatestSnapshot<MapCorrection>& channel = system_.loopCorrections();
  channel.writeBuffer() = closer_->correction();
  channel.publish(++corrections_published_);
}

void LoopStage::keyframeRetired(const RetiredKeyframe& kf, uint64_t epoch) {
  FinalPose f;
  f.id = kf.id;
  f.epoch = epoch;
  f.covariance_valid = kf.covariance_valid;
  f.T_world_cam = kf.T_world_cam;
  f.covariance = kf.covariance;
  // The final odometry edge is weighted by the covariance of the relative pose to the previous
  // keyframe (calibrated, docs/UNCERTAINTY.md) when local BA gave one.
  if (kf.uncertainty.hasRelative()) {
    f.covariance = kf.uncertainty.relative_covariance;
    f.covariance_valid = true;
  }
  if (synchronous_) {
    processFinal(f);
    return;
  }
  if (!final_ring_.try_push(f)) {
    ++dropped_;
    return;
  }
  doorbell_.ring();
}

void LoopStage::processFinal(const FinalPose& f) {
  closer_->keyframeFinal(f.id, f.T_world_cam, f.covariance, f.covariance_valid, f.epoch);
}

// Final poses first: they refer to keyframes whose records were pushed earlier (the map stage
// pushes a keyframe's record at insertion, its final pose ~32 keyframes later), so a final pose
// never overtakes its record.
bool LoopStage::popAndProcess() {
  FinalPose f;
  if (final_ring_.try_pop(f)) {
    processFinal(f);
    return true;
  }
  if (popped_ && ring_.try_pop(*popped_)) {
    process(*popped_);
    return true;
  }
  return false;
}

void LoopStage::threadMain() {
  if (thread_nice_ > 0) (void)runtime::setCurrentThreadNice(thread_nice_);
  for (;;) {
    doorbell_.waitUntil(
        [&] { return !final_ring_.empty() || !ring_.empty() || stop_.load(std::memory_order_acquire); });
    if (popAndProcess()) continue;
    // Stop requested and nothing left (the producer has finished before stop is set).
    if (stop_.load(std::memory_order_acquire)) {
      while (popAndProcess()) {
      }
      return;
    }
  }
}

void LoopStage::finish() {
  if (thread_.joinable()) {
    stop_.store(true, std::memory_order_release);
    doorbell_.ring();
    thread_.join();
  }
  synchronous_ = true;
}

}  // namespace plumb
