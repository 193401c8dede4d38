#pragma once
// Test helpers: run the odometry over a FrameSource through runOdometry() (pipeline/run/odometry_run.h,
// the composition `plumb run` uses) and collect the trajectory, per-frame outputs and counters.
// GeneratedSource makes a FrameSource of frames a test draws itself (blank frames, scene cuts).
#include <algorithm>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "drivers/common/frame_source.h"
#include "drivers/common/source_capture.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/trajectory/trajectory_io.h"
#include "pipeline/odometry/odometry_trajectory.h"
#include "pipeline/run/odometry_run.h"

namespace plumb::test {

struct OdometryRun {
  Status status;
  std::vector<StampedPose> trajectory;  // one per input frame, in order
  // The optimised trajectory (docs/LOOP.md): each frame through its reference keyframe's pose in
  // the final loop-closing graph; the real-time pose where the keyframe is not in the graph.
  std::vector<StampedPose> optimized;
  std::vector<FinishedFrame> finished;  // per frame, as the sink received it
  std::vector<FrameOutput> outputs;     // per frame as mapped (when asked for)
  OdometryStats stats;
  MapperStats mapper;
  OdometryRunResult result;
  std::size_t max_keyframes = 0, max_points = 0, max_lines = 0;  // largest counts seen per frame
};

// Collects what the runner delivers; reads the map counts on the map stage's thread.
class CollectingSink final : public OdometrySink {
 public:
  CollectingSink(bool keep_outputs, OdometryRun* run) : keep_outputs_(keep_outputs), run_(run) {}
  Status begin(const OdometrySystem& system) override {
    system_ = &system;
    return Status::Ok();
  }
  void onPose(const FrameOutput& out) override {
    if (on_pose) on_pose(out);
  }
  Status onFrame(const FrameOutput& out) override {
    if (on_frame) on_frame(out);
    if (keep_outputs_) run_->outputs.push_back(out);
    const MapCounts c = system_->mapCounts();
    run_->max_keyframes = std::max(run_->max_keyframes, c.keyframes);
    run_->max_points = std::max(run_->max_points, c.points);
    run_->max_lines = std::max(run_->max_lines, c.lines);
    return Status::Ok();
  }
  Status onFinishedFrame(const FinishedFrame& f) override {
    run_->trajectory.push_back(toStampedPose(f));
    run_->finished.push_back(f);
    return Status::Ok();
  }
  // Called first in onFrame(), on the map stage's thread (e.g. to make the map stage slow).
  std::function<void(const FrameOutput&)> on_frame;
  // Called in onPose(), on the track stage's thread.
  std::function<void(const FrameOutput&)> on_pose;

 private:
  const OdometrySystem* system_ = nullptr;
  bool keep_outputs_;
  OdometryRun* run_;
};

struct RunSettings {
  long max_frames = -1;
  runtime::RunMode mode = runtime::RunMode::kDeterministic;
  bool keep_outputs = false;
  bool loop_closing = true;
  int max_frames_ahead_of_mapper = -1;  // OdometryRunOptions: -1 = by mode
  std::function<void(const FrameOutput&)> on_frame;  // CollectingSink::on_frame
  std::function<void(const FrameOutput&)> on_pose;   // CollectingSink::on_pose
};

inline OdometryRun runOdometry(FrameSource& source, const SystemOptions& options, const RunSettings& settings = {}) {
  OdometryRun run;
  // Sized up front when the source knows its length, so the sink does not allocate per frame and
  // the run's own allocation count (OdometryRunResult::allocations_after_warmup) is the pipeline's.
  run.trajectory.reserve(source.frameCount());
  run.finished.reserve(source.frameCount());
  CollectingSink sink(settings.keep_outputs, &run);
  sink.on_frame = settings.on_frame;
  sink.on_pose = settings.on_pose;
  SourceCapture capture(source);
  OdometryRunOptions run_options;
  run_options.schedule.mode = settings.mode;
  run_options.max_frames = settings.max_frames;
  run_options.loop_closing = settings.loop_closing;
  run_options.max_frames_ahead_of_mapper = settings.max_frames_ahead_of_mapper;
  run.status = runOdometry(capture, options, sink, run_options, &run.result);
  run.optimized = run.trajectory;
  for (std::size_t i = 0; i < run.optimized.size(); ++i) {
    (void)run.result.loop.optimisedPose(run.finished[i], &run.optimized[i].T_world_cam);
  }
  run.stats = run.result.odometry;
  run.mapper = run.result.mapper;
  return run;
}

// A FrameSource of `count` frames drawn by `draw(index, image)` (which sets sequence and times).
class GeneratedSource final : public FrameSource {
 public:
  using DrawFn = std::function<Status(int index, RgbdImage& image)>;
  GeneratedSource(const PinholeCamera& camera, int count, DrawFn draw)
      : camera_(camera), count_(count), draw_(std::move(draw)) {}
  SourceResult next(RgbdImage& out) override {
    if (next_ >= count_) return SourceResult::kEndOfStream;
    error_ = draw_(next_++, out);
    return error_.ok() ? SourceResult::kFrame : SourceResult::kError;
  }
  const PinholeCamera& camera() const override { return camera_; }
  std::string describe() const override { return "generated"; }
  const Status& lastError() const override { return error_; }
  std::size_t frameCount() const override { return std::size_t(count_); }

 private:
  PinholeCamera camera_;
  int count_;
  DrawFn draw_;
  int next_ = 0;
  Status error_;
};

inline SynthOptions noisySynth(const std::string& preset, int frames) {
  SynthOptions o;
  o.preset = preset;
  o.frames = frames;
  o.depth_noise = true;
  o.depth_edge_holes = true;
  o.pixel_noise_sigma = 1.0;
  return o;
}

inline std::vector<StampedPose> groundTruth(const SyntheticScene& scene, int frames) {
  return syntheticGroundTruth(scene, frames);
}

inline double ateRmse(const std::vector<StampedPose>& gt, const std::vector<StampedPose>& est) {
  AteResult ate;
  const Status st = evaluateAte(gt, est, AteOptions{}, &ate);
  return st.ok() ? ate.translation_m.rmse : 1e9;
}

inline SystemOptions systemOptions(bool lines) {
  SystemOptions o;
  o.odometry.tracker.use_lines = lines;
  return o;
}

}  // namespace plumb::test
