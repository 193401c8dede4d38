#pragma once
// Monte Carlo NEES runs (docs/UNCERTAINTY.md): the odometry over a synthetic scene with known
// sensor noise, every published covariance collected as the covariance files would hold it, and
// NEES against the scene's exact ground truth. Shared by the CI test (tests/system/nees_test.cpp)
// and the study (bench/nees/, scripts/nees_study.sh).
#include <memory>
#include <vector>

#include "drivers/common/source_capture.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/trajectory/evaluate_nees.h"
#include "pipeline/odometry/odometry_trajectory.h"
#include "pipeline/odometry/published_covariance.h"
#include "pipeline/run/odometry_run.h"

namespace plumb::test {

// What `plumb run --covariance --track-covariance` would write, in memory.
class CovarianceCollectingSink final : public OdometrySink {
 public:
  Status onFrame(const FrameOutput& out) override {
    if (out.dropped || !out.has_pose) return Status::Ok();
    file.frames.push_back(toStampedTrackedCovariance(out));
    return Status::Ok();
  }
  Status onFinishedFrame(const FinishedFrame& f) override {
    trajectory.push_back(toStampedPose(f));
    return Status::Ok();
  }
  Status onRetiredKeyframe(const RetiredKeyframe& kf) override {
    file.keyframes.push_back(toStampedCovariance(kf));
    return Status::Ok();
  }
  CovarianceFile file;
  std::vector<StampedPose> trajectory;
};

struct NeesRun {
  Status status;
  NeesResult nees;
  double ate_m = 0;
  std::size_t frames_with_pose = 0;
};

// Kinect-like noise (the renderer's own model: the truth the estimator is calibrated against).
inline SynthOptions kinectSynth(const std::string& preset, uint64_t seed, int frames) {
  SynthOptions o;
  o.preset = preset;
  o.seed = seed;
  o.frames = frames;
  enableKinectNoise(&o);
  return o;
}

// Poses are output as tracked (output delay 0: what MAVLink sends), loop closing off (a correction
// moves the world frame, which no published covariance describes).
inline NeesRun runSyntheticNees(const SynthOptions& synth, SystemOptions system_options) {
  NeesRun run;
  std::unique_ptr<SyntheticSource> source;
  run.status = SyntheticSource::create(synth, &source);
  if (!run.status.ok()) return run;
  system_options.output_delay_frames = 0;
  CovarianceCollectingSink sink;
  SourceCapture capture(*source);
  OdometryRunOptions run_options;
  run_options.loop_closing = false;
  OdometryRunResult result;
  run.status = runOdometry(capture, system_options, sink, run_options, &result);
  if (!run.status.ok()) return run;
  const std::vector<StampedPose> gt = syntheticGroundTruth(source->scene(), synth.frames);
  StampedPose anchor;
  anchor.valid = false;
  for (const StampedPose& p : sink.trajectory) {
    run.frames_with_pose += p.valid ? 1 : 0;
    if (p.valid && !anchor.valid) anchor = p;
  }
  AteResult ate;
  if (evaluateAte(gt, sink.trajectory, AteOptions{}, &ate).ok()) run.ate_m = ate.translation_m.rmse;
  run.status = evaluateNees(gt, sink.file, anchor, NeesOptions{}, &run.nees);
  return run;
}

// Pools runs' statistics of one quantity: means weighted by sample counts.
struct PooledNees {
  std::size_t count = 0;
  double sum_per_dof = 0, sum_inside = 0, sum_translation = 0, sum_rotation = 0;
  void add(const NeesStatistics& s) {
    count += s.count;
    sum_per_dof += s.mean_per_dof * double(s.count);
    sum_inside += s.inside_95 * double(s.count);
    sum_translation += s.translation_mean_per_dof * double(s.count);
    sum_rotation += s.rotation_mean_per_dof * double(s.count);
  }
  double meanPerDof() const { return count ? sum_per_dof / double(count) : 0.0; }
  double inside95() const { return count ? sum_inside / double(count) : 0.0; }
  double translationPerDof() const { return count ? sum_translation / double(count) : 0.0; }
  double rotationPerDof() const { return count ? sum_rotation / double(count) : 0.0; }
};

}  // namespace plumb::test
