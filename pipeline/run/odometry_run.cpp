#include "pipeline/run/odometry_run.h"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <chrono>
#include <string>

#include "pipeline/run/loop_stage.h"
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
  if (options.max_frames_ahead_of_mapper < -1 || options.max_frames_ahead_of_mapper > 64) {
    return Status::Error("max_frames_ahead_of_mapper must be within 0..64 (or -1: by mode)");
  }
  if (options.save_map != nullptr && !options.loop_closing) {
    return Status::Error("saving a map needs loop closing (the map is the loop closer's keyframe graph)");
  }
  if (options.load_map != nullptr && options.load_map->keyframes.empty()) {
    return Status::Error("the loaded map holds no keyframes: nothing to relocalize against");
  }
  return Status::Ok();
}

bool LoopRunResult::keyframeFinalPose(uint32_t id, uint64_t epoch, Eigen::Isometry3d* T_world_graph,
                                      Eigen::Isometry3d* T_world_final) const {
  const auto it = std::lower_bound(keyframes.begin(), keyframes.end(), id,
                                   [](const std::pair<uint32_t, Eigen::Isometry3d>& k, uint32_t v) { return k.first < v; });
  if (it == keyframes.end() || it->first != id) return false;
  const FinalPose& f = keyframe_finals[std::size_t(it - keyframes.begin())];
  if (!f.has_final || f.epoch != epoch) return false;
  *T_world_graph = it->second;
  *T_world_final = f.T_world_cam;
  return true;
}

bool LoopRunResult::optimisedPose(const FinishedFrame& frame, Eigen::Isometry3d* T_world_cam) const {
  if (!frame.valid || frame.reference_id == 0) return false;
  Eigen::Isometry3d T_world_ref, T_world_ref_final;
  if (keyframeFinalPose(frame.reference_id, frame.loop_epoch, &T_world_ref, &T_world_ref_final)) {
    // Both in the frame's world: without loops the graph is the local map's final chain, so this
    // is the real-time pose up to one rigid motion, and BA's late changes to a keyframe do not
    // move frames tracked (and output) long before them.
    *T_world_cam = T_world_ref * T_world_ref_final.inverse() * frame.T_world_cam;
    return true;
  }
  if (!keyframePose(frame.reference_id, &T_world_ref)) return false;
  *T_world_cam = T_world_ref * frame.T_ref_cam;
  return true;
}

bool LoopRunResult::keyframePose(uint32_t id, Eigen::Isometry3d* T_world_cam) const {
  const auto it = std::lower_bound(keyframes.begin(), keyframes.end(), id,
                                   [](const std::pair<uint32_t, Eigen::Isometry3d>& k, uint32_t v) { return k.first < v; });
  if (it == keyframes.end() || it->first != id) return false;
  *T_world_cam = it->second;
  return true;
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
  // The trace is read only for `--profile` (keep_trace). Without it, reserving it would cost
  // 40 B x 8192 per stage that a long run fills and makes resident frame after frame.
  if (!options.keep_trace) schedule.trace_capacity_per_stage = 0;
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
  const bool realtime = schedule.mode == runtime::RunMode::kRealtime;
  int frames_ahead = options.max_frames_ahead_of_mapper;
  if (frames_ahead < 0) frames_ahead = realtime ? OdometryRunOptions::kRealtimeFramesAhead : 0;
  MapperFence fence(!lock_step && !simulated, frames_ahead);
  CaptureStage capture_stage(capture, options.max_frames, options.stop, drops);
  ExtractStage extract(system);
  TrackStage track(system, fence, sink);
  std::unique_ptr<LoopStage> loop;
  if (options.loop_closing) {
    // Its own thread only in real time (off the latency path like the map stage: nice 5), not in
    // its one-thread simulation. Fast mode runs it on the map stage's thread, in lock-step with
    // the map as in deterministic mode: a correction then reaches the same frame's map as there,
    // which keeps fast mode's output the deterministic output.
    loop = std::make_unique<LoopStage>(system, options.loop, realtime && !simulated, realtime ? 5 : 0);
  }
  if (options.load_map != nullptr) {
    const auto restore_start = std::chrono::steady_clock::now();
    const std::string mismatch = loop::cameraMismatch(options.load_map->camera, system.camera());
    if (!mismatch.empty()) {
      return Status::Error("the map was made with another camera: " + mismatch);
    }
    if (loop) PLUMB_RETURN_IF_ERROR(loop->restoreMap(*options.load_map).withContext("loading the map"));
    // The relocalizer keeps its ring's worth (the newest keyframes when the map holds more).
    std::vector<Eigen::Vector3f> points;
    points.reserve(loop::kMaxLoopPoints);
    for (const auto& k : options.load_map->keyframes) {
      points.clear();
      for (const loop::LoopPoint& p : k->record.points) points.push_back(p.P_cam);
      system.addLoadedKeyframe(k->record.id, k->T_world_cam, points.size(), k->record.point_descriptors.data(),
                               points.data());
    }
    // New keyframe ids leave a gap of the loop closer's minimum candidate age after the loaded
    // ones: the closer skips candidates that young (the local window), but a loaded keyframe is
    // never in this run's window, so the very first new keyframes may already close a loop into
    // the loaded map (ids only need to grow).
    system.beginInLoadedMap(options.load_map->maxKeyframeId() + 1 + uint32_t(std::max(0, options.loop.min_age_keyframes)));
    result->map_restore_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - restore_start).count();
  }
  if (loop) loop->start();
  MapStage map(system, fence, drops, sink, options.warmup_frames, loop.get());
  runtime::StageRunner<OdometrySlot> runner(capture_stage, {&extract, &track, &map}, schedule);
  Status status = runner.run();
  if (status.ok()) status = map.finishStatus();
  if (loop) {
    // The loop stage catches up; its last correction reaches the map before the final poses.
    loop->finish();
    system.applyLoopCorrection();
  }

  // Whatever ended the run, every pose computed so far (those held back for refinement too) and
  // every keyframe reach the sink.
  Status finish_status;
  system.finish(
      [&](const FinishedFrame& f) {
        if (finish_status.ok()) finish_status = sink.onFinishedFrame(f);
      },
      [&](const RetiredKeyframe& kf) {
        if (loop) loop->keyframeRetired(kf, system.stats().loop_corrections_applied);
        if (finish_status.ok()) finish_status = sink.onRetiredKeyframe(kf);
      });
  if (status.ok()) status = finish_status;
  if (loop) {
    loop->finalOptimise();
    LoopRunResult& r = result->loop;
    r.enabled = true;
    r.stats = loop->stats();
    r.records_dropped = loop->recordsDropped();
    r.corrections_published = loop->correctionsPublished();
    r.capacity = loop->closer().capacity();
    r.memory_bytes = loop->closer().memoryBytes();
    const loop::LoopAudit& audit = loop->closer().audit();
    r.audit = audit.entries();
    r.audit_keyframes = audit.keyframes();
    r.audit_entries_dropped = audit.entriesDropped();
    r.audit_keyframes_dropped = audit.keyframesDropped();
    r.keyframes.clear();
    r.keyframe_finals.clear();
    r.keyframes.reserve(loop->closer().size());
    for (std::size_t i = 0; i < loop->closer().size(); ++i) {
      Eigen::Isometry3d T;
      const uint32_t id = loop->closer().idAt(i);
      if (!loop->closer().pose(id, &T)) continue;
      r.keyframes.emplace_back(id, T);
      LoopRunResult::FinalPose f;
      f.has_final = loop->closer().finalPose(id, &f.T_world_cam, &f.epoch);
      r.keyframe_finals.push_back(f);
    }
    if (options.save_map != nullptr) {
      loop->closer().exportMap(options.save_map);
      options.save_map->camera = system.camera();
    }
  }

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
