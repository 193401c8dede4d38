#pragma once
// RunSession: one odometry run's objects and its protocol, in one place. It owns the system, the
// register (depth not registered to colour only) / extract / track / map stages (pipeline/run/odometry_stages.h; threaded runs: two extract stages,
// even and odd frames), the loop stage and the MapperFence, and is driven one of two ways:
//
//   run(capture)  the whole input through runtime::StageRunner in the options' schedule
//                 (runOdometry(), pipeline/run/odometry_run.h: `plumb run`, tests, benchmarks);
//   step()        one frame the caller wrote into slot().image, lock-step (the public API,
//                 api/plumb/odometry.h): the calls and their order are exactly the lock-step
//                 schedule's, so both give the same bytes;
//
// and both end in finish(), the one end-of-run protocol: the map stage writes the frames dropped
// last -> the loop stage catches up -> its last correction reaches the map -> every frame held back
// for refinement, then every keyframe, reach the sink (retired keyframes also the loop closer) ->
// the loop closer's final optimisation -> the result (and --save-map's map) is filled.
//
//   std::unique_ptr<RunSession> session;
//   RunSession::create(camera, system_options, sink, run_options, &session);
//   session->run(capture);                   // or: fill session->slot().image; session->step(); ...
//   session->finish();                       // run() has called it already
//   session->result();
#include <cstdint>
#include <memory>

#include "pipeline/odometry/mapper_fence.h"
#include "pipeline/run/loop_stage.h"
#include "pipeline/run/odometry_run.h"
#include "pipeline/run/odometry_stages.h"
#include "platform/status.h"
#include "sensor/frame_capture.h"

namespace plumb {

class RunSession {
 public:
  // Checks `options` (validate(OdometryRunOptions)), builds the system (OdometrySystem::create
  // checks the system options and the camera), fills the loop closer and the relocalizer from
  // options.load_map (its camera must be `camera`), then calls sink.begin(). `sink` must outlive
  // the session. Sets OpenCV to no worker threads (process-wide): the stages are the parallelism
  // and the output must not depend on a pool.
  static Status create(const PinholeCamera& camera, const SystemOptions& system_options, OdometrySink& sink,
                       const OdometryRunOptions& options, std::unique_ptr<RunSession>* out);
  ~RunSession();
  RunSession(const RunSession&) = delete;
  RunSession& operator=(const RunSession&) = delete;

  // Every frame of `capture` (to its end, options.max_frames or options.stop) through the stage
  // runner, then finish(). Once, and not after step().
  Status run(FrameCapture& capture);

  // Push style, deterministic schedule only. The frame to fill before step(): bgr (CV_8UC3, camera
  // size), depth_raw (CV_16UC1, the depth camera's size: camera.depthWidth() x depthHeight()) and
  // timestamp_s; sequence and the stamps are set by step().
  OdometrySlot& slot();
  // One frame through extract, track (sink.onPose) and map (sink.onFrame, ...). The tracked result
  // is slot().tracked->output. After warm-up a step allocates nothing.
  Status step();

  // End of input, whatever ended it (see the top of this file). Idempotent.
  Status finish();

  // Complete after finish(); frames() and extractionFailures() are current at any time.
  const OdometryRunResult& result() const { return result_; }
  OdometryRunResult takeResult() { return std::move(result_); }
  const OdometrySystem& system() const { return *system_; }
  uint64_t frames() const { return map_.frames(); }
  uint64_t extractionFailures() const;

 private:
  RunSession(std::unique_ptr<OdometrySystem> system, OdometrySink& sink, const OdometryRunOptions& options);
  Status restoreLoadedMap();

  OdometryRunOptions options_;
  std::unique_ptr<OdometrySystem> system_;
  OdometrySink& sink_;
  DropLog drops_;
  MapperFence fence_;
  RegisterStage register_;                      // unregistered depth cameras only (needed())
  ExtractStage extract_;                        // every frame; threaded runs: the even ones
  std::unique_ptr<ExtractStage> extract_odd_;   // threaded runs: the odd frames, on a thread of its own
  TrackStage track_;
  std::unique_ptr<LoopStage> loop_;  // before map_, which is given it; nullptr: loop closing off
  MapStage map_;
  std::unique_ptr<OdometrySlot> push_slot_;  // step(): made by the first slot()
  OdometryRunResult result_;
  enum class Use : uint8_t { kNone, kRun, kStep };
  Use use_ = Use::kNone;  // run() and step() exclude each other
  bool finished_ = false;
};

}  // namespace plumb
