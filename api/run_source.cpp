// plumb::api::runSource: the staged runtime (runOdometry, any mode) behind the public API, with
// the poses delivered to the caller's callbacks.
#include <memory>

#include "api/api_convert.h"
#include "api/plumb/odometry.h"
#include "drivers/common/source_capture.h"
#include "drivers/open/open_source.h"
#include "pipeline/run/odometry_run.h"

namespace plumb::api {
namespace {

class CallbackSink final : public OdometrySink {
 public:
  CallbackSink(const std::function<void(const TrackOutput&)>& on_pose,
               const std::function<void(const FinishedPose&)>& on_finished)
      : on_pose_(on_pose), on_finished_(on_finished) {}
  void onPose(const FrameOutput& frame) override {
    if (!on_pose_) return;
    toTrackOutput(frame, &pose_);  // a member: no allocation per frame
    on_pose_(pose_);
  }
  ::plumb::Status onFinishedFrame(const FinishedFrame& frame) override {
    if (on_finished_) on_finished_(toFinished(frame));
    return ::plumb::Status::Ok();
  }

 private:
  const std::function<void(const TrackOutput&)>& on_pose_;
  const std::function<void(const FinishedPose&)>& on_finished_;
  TrackOutput pose_;
};

}  // namespace

Status runSource(const RunConfig& config, const std::function<void(const TrackOutput&)>& on_pose,
                 const std::function<void(const FinishedPose&)>& on_finished, RunSummary* summary) {
  OdometryRunOptions run_options;
  Status st = fromStatus(runtime::parseRunMode(config.mode, &run_options.schedule.mode));
  if (!st.ok) return st;
  run_options.max_frames = config.max_frames;
  st = fromStatus(validate(run_options));
  if (!st.ok) return st;
  std::unique_ptr<FrameSource> source;
  st = fromStatus(openFrameSource(config.source, config.camera, &source));
  if (!st.ok) return st;
  CallbackSink sink(on_pose, on_finished);
  SourceCapture capture(*source);
  OdometryRunResult result;
  st = fromStatus(runOdometry(capture, systemOptions(config.lines, config.line_samples, config.output_delay_frames),
                              sink, run_options, &result));
  if (summary != nullptr) {
    summary->counters = toCounters(result.odometry, result.frames, result.extraction_failures);
    summary->frames_dropped = result.frames_dropped;
    summary->frames_per_second = result.report.framesPerSecond();
  }
  return st;
}

}  // namespace plumb::api
