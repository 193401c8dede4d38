#pragma once
// RunOutputs: where `plumb run` and `plumb demo` send what the runner (pipeline/run/odometry_run.h)
// produces: the TUM trajectory file, the keyframe covariance file, the poses kept in memory for the
// ATE, statistics, and the --trace / --progress lines. Glue only: the formats live in
// drivers/trajectory/, the statistics in pipeline/run/run_statistics.h.
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "drivers/common/frame_source.h"
#include "drivers/mavlink/mavlink_odometry_sink.h"
#include "drivers/trajectory/covariance_io.h"
#include "drivers/trajectory/trajectory_io.h"
#include "pipeline/run/odometry_run.h"
#include "pipeline/run/run_statistics.h"

namespace plumb::tools {

struct RunOutputOptions {
  std::string trajectory_path;  // TUM file, one line per input frame ('' = none)
  std::string covariance_path;  // one line per keyframe ('' = none)
  std::string track_covariance_path;  // one line per tracked frame ('' = none)
  // The optimised trajectory (docs/LOOP.md): every frame through its reference keyframe's pose in
  // the final pose graph, written at the end of the run ('' = none).
  std::string optimized_path;
  bool keep_trajectory = true;  // poses in memory (for the ATE); off for very long runs
  // Frames the run will see (0: unknown): the progress line's ETA, and the poses reserved at
  // start (at most kMaxReservedPoses: a flag like --max-frames 10^12 over a recording of unknown
  // length is never a size to allocate; beyond it the vector grows, rarely, by doubling).
  std::size_t expected_frames = 0;
  long rss_every = 0;           // > 0: an RSS checkpoint every this many frames
  // A progress line on stderr (frames, frames/s, ETA). On a terminal it is one line rewritten in
  // place at most 4 times a second; otherwise a line every 100 frames.
  bool progress = false;
  bool progress_on_terminal = false;
  bool trace = false;           // a line per frame on stderr (matches, inliers, keyframes, pose)
  // > 0: every this many frames a line on stdout with the block's sensor-to-pose p99, drops and
  // resident memory (soak tests: scripts/soak.sh).
  long report_every = 0;
  // MAVLink ODOMETRY to an autopilot (docs/MAVLINK.md): endpoint '' = off.
  MavlinkOptions mavlink;
};

class RunOutputs final : public OdometrySink {
 public:
  explicit RunOutputs(const RunOutputOptions& options);
  ~RunOutputs() override;
  static constexpr std::size_t kMaxReservedPoses = 108'000;  // an hour at 30 Hz
  // Opens the files; called by the run session once the run has been checked (a refused run
  // opens none).
  Status begin(const OdometrySystem&) override;
  // Flushes and closes them, under their names (keep) or not at all (abandon: the run produced
  // nothing valid, e.g. it failed before its first frame; an older file of that name stays).
  // Nothing when they were never opened.
  Status close(bool keep = true);
  bool anyFile() const {
    return !options_.trajectory_path.empty() || !options_.covariance_path.empty() ||
           !options_.track_covariance_path.empty() || !options_.optimized_path.empty();
  }
  void endProgress();  // ends the terminal's progress line

  void onPose(const FrameOutput& frame) override;
  Status onFrame(const FrameOutput& frame) override;
  Status onFinishedFrame(const FinishedFrame& frame) override;
  Status onRetiredKeyframe(const RetiredKeyframe& keyframe) override;

  // End of run: writes --out-optimized from the frames streamed during the run and the final graph
  // (keeps those poses for the ATE when keep_trajectory). Frames whose reference keyframe is not in
  // the graph (no loop closing, culled, never received) keep their real-time pose (counted).
  Status writeOptimized(const LoopRunResult& loop);
  const std::vector<StampedPose>& optimizedTrajectory() const { return optimized_; }
  uint64_t optimizedWithoutKeyframe() const { return optimized_without_keyframe_; }

  const std::vector<StampedPose>& trajectory() const { return trajectory_; }
  const RunStatistics& statistics() const { return statistics_; }
  const MavlinkOdometrySink* mavlink() const { return mavlink_.get(); }  // nullptr when off

 private:
  void reportBlock(const FrameOutput& frame);
  void progressLine(uint64_t frame, const FrameOutput& out);

  RunOutputOptions options_;
  bool opened_ = false;
  TumTrajectoryWriter trajectory_writer_;
  CovarianceWriter covariance_writer_;
  CovarianceWriter track_covariance_writer_;
  std::vector<StampedPose> trajectory_;
  // --out-optimized: one fixed-size record per finished frame in an anonymous temporary file
  // (std::tmpfile: removed by the OS however the process ends), so memory stays flat.
  std::FILE* frames_stream_ = nullptr;
  std::vector<StampedPose> optimized_;
  uint64_t optimized_without_keyframe_ = 0;
  RunStatistics statistics_;
  std::unique_ptr<MavlinkOdometrySink> mavlink_;
  // --report-every, on the track stage's thread (onPose); drops arrive on the map stage's.
  runtime::LatencyHistogram block_latency_;
  uint64_t block_frames_ = 0, blocks_ = 0;
  std::atomic<uint64_t> dropped_total_{0};
  uint64_t dropped_at_block_start_ = 0;
  uint64_t keyframes_ = 0, lost_ = 0;
  int64_t progress_start_ns_ = 0, progress_last_ns_ = 0;
  bool progress_line_open_ = false;
};

// What a run leaves besides its outputs.
struct RunRecord {
  OdometryRunResult run;
  OdometryStats odometry;
  MapperStats mapper;
  uint64_t mapper_waits = 0;  // threaded runs: times tracking waited for a lagging map stage
  // The output files: written under their names (false: the run produced no frame, nothing was
  // replaced), and how that went (a full disk: nothing under the names either).
  bool outputs_kept = false;
  Status outputs_status;
};

// Runs `source` through runOdometry() (pipeline/run/odometry_run.h: system, session, runner) into
// `outputs` (opened when the run has been checked, closed after, also when the run failed: what
// was computed is kept; a run that produced no frame replaces no file). The options were validated
// by the caller's plan (tools/run_plan.cpp).
// `sink`: what the run calls when not `outputs` itself, i.e. a decorator that forwards to
// `outputs` (the viewer's, viewer/viewer_sink.h); nullptr: `outputs`.
Status runToOutputs(FrameSource& source, const SystemOptions& system_options, const OdometryRunOptions& run_options,
                    RunOutputs& outputs, RunRecord* record, OdometrySink* sink = nullptr);

}  // namespace plumb::tools
