#include "pipeline/run/run_session.h"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "runtime/stage_runner.h"

namespace plumb {

namespace {

bool isRealtime(const runtime::RunOptions& s) { return s.mode == runtime::RunMode::kRealtime; }

// Every stage on one thread: lock-step, and the simulation of real time on a VirtualClock (nobody
// else could move the map stage on, so the fence must not wait).
bool oneThread(const runtime::RunOptions& s) {
  const bool simulated = isRealtime(s) && s.clock != nullptr && s.clock->isVirtual();
  return s.mode == runtime::RunMode::kDeterministic || simulated;
}

MapperFence fenceFor(const OdometryRunOptions& options) {
  int frames_ahead = options.max_frames_ahead_of_mapper;
  if (frames_ahead < 0) frames_ahead = isRealtime(options.schedule) ? OdometryRunOptions::kRealtimeFramesAhead : 0;
  return MapperFence(!oneThread(options.schedule), frames_ahead);
}

std::unique_ptr<LoopStage> loopStageFor(OdometrySystem& system, const OdometryRunOptions& options) {
  if (!options.loop_closing) return nullptr;
  // Its own thread only in real time (off the latency path like the map stage: nice 5), not in
  // its one-thread simulation. Fast mode runs it on the map stage's thread, in lock-step with the
  // map as in deterministic mode: a correction then reaches the same frame's map as there, which
  // keeps fast mode's output the deterministic output.
  const bool realtime = isRealtime(options.schedule);
  return std::make_unique<LoopStage>(system, options.loop, realtime && !oneThread(options.schedule), realtime ? 5 : 0);
}

}  // namespace

RunSession::RunSession(std::unique_ptr<OdometrySystem> system, OdometrySink& sink, const OdometryRunOptions& options)
    : options_(options),
      system_(std::move(system)),
      sink_(sink),
      fence_(fenceFor(options)),
      register_(system_->camera()),
      // Threaded: two extract stages, even and odd frames, so that extraction (the largest stage,
      // about half of a frame's work) is not the pipeline's bottleneck on two cores.
      extract_(*system_, oneThread(options.schedule) ? 1 : 2, 0),
      extract_odd_(oneThread(options.schedule) ? nullptr : std::make_unique<ExtractStage>(*system_, 2, 1)),
      track_(*system_, fence_, sink),
      loop_(loopStageFor(*system_, options)),
      map_(*system_, fence_, drops_, sink, options.warmup_frames, loop_.get()) {}

RunSession::~RunSession() = default;

Status RunSession::create(const PinholeCamera& camera, const SystemOptions& system_options, OdometrySink& sink,
                          const OdometryRunOptions& options, std::unique_ptr<RunSession>* out) {
  PLUMB_RETURN_IF_ERROR(validate(options));
  std::unique_ptr<OdometrySystem> system;
  PLUMB_RETURN_IF_ERROR(OdometrySystem::create(camera, system_options, &system));
  std::unique_ptr<RunSession> session(new RunSession(std::move(system), sink, options));
  PLUMB_RETURN_IF_ERROR(session->restoreLoadedMap());
  // The stages are the parallelism: OpenCV's own worker pool would compete with them for the
  // cores, and each fresh pool worker allocates thread-local state the first time it runs a
  // cv::parallel_for_ body, i.e. at unpredictable frames of a steady run.
  cv::setNumThreads(0);
  PLUMB_RETURN_IF_ERROR(sink.begin(*session->system_));
  if (session->loop_) session->loop_->start();
  *out = std::move(session);
  return Status::Ok();
}

Status RunSession::restoreLoadedMap() {
  const loop::SavedMap* map = options_.load_map;
  if (map == nullptr) return Status::Ok();
  const auto restore_start = std::chrono::steady_clock::now();
  const std::string mismatch = loop::cameraMismatch(map->camera, system_->camera());
  if (!mismatch.empty()) return Status::Error("the map was made with another camera: " + mismatch);
  if (loop_) PLUMB_RETURN_IF_ERROR(loop_->restoreMap(*map).withContext("loading the map"));
  // The relocalizer keeps its ring's worth (the newest keyframes when the map holds more).
  std::vector<Eigen::Vector3f> points;
  points.reserve(loop::kMaxLoopPoints);
  for (const auto& k : map->keyframes) {
    points.clear();
    for (const loop::LoopPoint& p : k->record.points) points.push_back(p.P_cam);
    system_->addLoadedKeyframe(k->record.id, k->T_world_cam, points.size(), k->record.point_descriptors.data(),
                               points.data());
  }
  // New keyframe ids leave a gap of the loop closer's minimum candidate age after the loaded
  // ones: the closer skips candidates that young (the local window), but a loaded keyframe is
  // never in this run's window, so the very first new keyframes may already close a loop into
  // the loaded map (ids only need to grow).
  system_->beginInLoadedMap(map->maxKeyframeId() + 1 + uint32_t(std::max(0, options_.loop.min_age_keyframes)));
  result_.map_restore_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - restore_start).count();
  return Status::Ok();
}

uint64_t RunSession::extractionFailures() const {
  return register_.failures() + extract_.failures() + (extract_odd_ ? extract_odd_->failures() : 0);
}

Status RunSession::run(FrameCapture& capture) {
  if (use_ != Use::kNone) return Status::Error("run session: run() on a session that has already run or stepped");
  use_ = Use::kRun;
  runtime::RunOptions schedule = options_.schedule;
  // Lock-step: each frame leaves the pipeline before the next is read, one slot is all it uses.
  if (schedule.mode == runtime::RunMode::kDeterministic) schedule.slot_count = 1;
  // The trace is read only for `--profile` (keep_trace). Without it, reserving it would cost
  // 40 B x 8192 per stage that a long run fills and makes resident frame after frame.
  if (!options_.keep_trace) schedule.trace_capacity_per_stage = 0;
  // A camera whose depth is not registered to colour gets a register stage before extraction
  // (its own thread in the threaded modes, its own trace track and report row); others run
  // without it, exactly as before it existed.
  std::vector<runtime::Stage<OdometrySlot>*> stages;
  if (register_.needed()) stages.push_back(&register_);
  stages.push_back(&extract_);
  if (extract_odd_) stages.push_back(extract_odd_.get());
  stages.push_back(&track_);
  const int track_stage = int(stages.size());  // runner numbering: 0 = capture
  stages.push_back(&map_);
  // Real time: mapping is off the latency path (poses are known when tracking is done), so under
  // contention the kernel serves capture, extract and track first. Nice 5, not more: the map stage
  // must still keep up on average, or the slots fill and frames drop. Not in fast mode, where every
  // stage is on the throughput path.
  if (isRealtime(schedule)) {
    schedule.background_stages = 1u << (track_stage + 1);
    schedule.background_nice = 5;
  }
  // End to end = sensor time to pose known (track done); the map stage refines later frames' map.
  schedule.end_to_end_stage = track_stage;

  CaptureStage capture_stage(capture, options_.max_frames, options_.stop, drops_);
  runtime::StageRunner<OdometrySlot> runner(capture_stage, stages, schedule);
  // Registered-depth buffers sized once, with the pool (registerInto() then never allocates).
  if (register_.needed()) {
    const PinholeCamera& camera = system_->camera();
    for (std::size_t i = 0; i < runner.pool().size(); ++i) {
      runner.pool()[runtime::SlotIndex(i)].payload.registered_depth.create(camera.height, camera.width, CV_16UC1);
    }
  }
  Status status = runner.run();
  const Status finished = finish();
  if (status.ok()) status = finished;
  result_.report = runner.report();
  if (options_.keep_trace) result_.trace = runner.trace();
  result_.stopped = capture_stage.stopped();
  return status;
}

OdometrySlot& RunSession::slot() {
  if (!push_slot_) {
    push_slot_ = std::make_unique<OdometrySlot>();
    const PinholeCamera& camera = system_->camera();
    push_slot_->image.bgr.create(camera.height, camera.width, CV_8UC3);
    push_slot_->image.depth_raw.create(camera.depthHeight(), camera.depthWidth(), CV_16UC1);
    if (register_.needed()) push_slot_->registered_depth.create(camera.height, camera.width, CV_16UC1);
    push_slot_->image.depth_factor = camera.depth_factor;
  }
  return *push_slot_;
}

Status RunSession::step() {
  if (finished_) return Status::Error("run session: step() after finish()");
  if (options_.schedule.mode != runtime::RunMode::kDeterministic) {
    return Status::Error("run session: step() needs the deterministic (lock-step) schedule");
  }
  if (use_ == Use::kRun) return Status::Error("run session: step() after run()");
  use_ = Use::kStep;
  OdometrySlot& s = slot();
  const uint64_t index = map_.frames();
  runtime::FrameStamps stamps;
  stamps.frame_index = index;
  stamps.t_recorded_ns = int64_t(s.image.timestamp_s * 1e9);
  s.image.sequence = index;
  s.dropped_before = 0;
  // The runner's lock-step order (runtime::StageRunner in deterministic mode).
  if (register_.needed()) PLUMB_RETURN_IF_ERROR(register_.process(s, stamps));
  PLUMB_RETURN_IF_ERROR(extract_.process(s, stamps));
  PLUMB_RETURN_IF_ERROR(track_.process(s, stamps));
  return map_.process(s, stamps);
}

Status RunSession::finish() {
  if (finished_) return Status::Ok();
  finished_ = true;
  // After run() the runner has called it at the end of the stream (unless the map stage failed).
  if (use_ != Use::kRun) map_.finish();
  Status status = map_.finishStatus();
  if (loop_) {
    // The loop stage catches up; its last correction reaches the map before the final poses.
    loop_->finish();
    system_->applyLoopCorrection();
  }
  // Whatever ended the run, every pose computed so far (those held back for refinement too) and
  // every keyframe reach the sink.
  const Status rest = map_.deliverTheRest();
  if (status.ok()) status = rest;
  if (loop_) {
    loop_->finalOptimise();
    LoopRunResult& r = result_.loop;
    r.enabled = true;
    r.stats = loop_->stats();
    r.records_dropped = loop_->recordsDropped();
    r.corrections_published = loop_->correctionsPublished();
    r.capacity = loop_->closer().capacity();
    r.memory_bytes = loop_->closer().memoryBytes();
    const loop::LoopAudit& audit = loop_->closer().audit();
    r.audit = audit.entries();
    r.audit_keyframes = audit.keyframes();
    r.audit_entries_dropped = audit.entriesDropped();
    r.audit_keyframes_dropped = audit.keyframesDropped();
    r.keyframes.clear();
    r.keyframe_finals.clear();
    r.epoch_corrections = system_->appliedCorrections();
    r.keyframes.reserve(loop_->closer().size());
    for (std::size_t i = 0; i < loop_->closer().size(); ++i) {
      Eigen::Isometry3d T;
      const uint32_t id = loop_->closer().idAt(i);
      if (!loop_->closer().pose(id, &T)) continue;
      r.keyframes.emplace_back(id, T);
      LoopRunResult::FinalPose f;
      f.has_final = loop_->closer().finalPose(id, &f.T_world_cam, &f.epoch);
      r.keyframe_finals.push_back(f);
    }
    if (options_.save_map != nullptr) {
      loop_->closer().exportMap(options_.save_map);
      options_.save_map->camera = system_->camera();
    }
  }
  result_.frames = map_.frames();
  result_.frames_dropped = map_.framesDropped();
  result_.extraction_failures = extractionFailures();
  result_.drops_without_trajectory_line = drops_.not_logged;
  const uint64_t counted = map_.framesAfterWarmup();
  result_.allocation_frames = counted > 0 ? counted - 1 : 0;
  result_.allocations_after_warmup = map_.allocationsAfterWarmup();
  result_.odometry = system_->stats();
  result_.mapper = system_->mapperStats();
  result_.mapper_waits = system_->mapperWaits();
  return status;
}

}  // namespace plumb
