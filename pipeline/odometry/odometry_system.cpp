#include "pipeline/odometry/odometry_system.h"

#include <chrono>
#include <cmath>
#include <string>

namespace plumb {

namespace {

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Status validate(const SystemOptions& options) {
  const std::string extractor = validate(options.odometry.extractor);
  if (!extractor.empty()) return Status::Error("extractor options: " + extractor);
  if (options.odometry.extractor.line_samples == 1) {
    // A line landmark is a 3D line fitted through its samples: one sample fixes no direction, so
    // N = 1 could only ever mean "no lines" -- refused rather than silently changed.
    return Status::Error("line samples must be 0 (points only) or 2.." + std::to_string(kMaxLineSamples) +
                         ": a 3D line needs at least two samples");
  }
  if (options.odometry.extractor.line_samples > 0 &&
      options.odometry.extractor.min_line_inliers > options.odometry.extractor.line_samples) {
    return Status::Error("min_line_inliers (" + std::to_string(options.odometry.extractor.min_line_inliers) +
                         ") exceeds line_samples (" + std::to_string(options.odometry.extractor.line_samples) +
                         "): no line could ever be fitted");
  }
  if (options.map_lag_frames < 1 || options.map_lag_frames > SystemOptions::kMaxMapLagFrames) {
    return Status::Error("map lag must be within 1.." + std::to_string(SystemOptions::kMaxMapLagFrames) + " frames");
  }
  if (options.refine_lag_frames < 0 || options.refine_lag_frames > SystemOptions::kMaxRefineLagFrames) {
    return Status::Error("refine lag must be within 0.." + std::to_string(SystemOptions::kMaxRefineLagFrames) +
                         " frames");
  }
  if (options.refine_lag_frames > 0 && options.map_lag_frames != 1) {
    // With L > 1 a later request's fresh map could be due after an earlier refined one that the
    // mapper has already overwritten: the rule would not be one order in every schedule.
    return Status::Error("a map lag of " + std::to_string(options.map_lag_frames) +
                         " frames needs refine lag 0 (split map updates need map lag 1)");
  }
  const std::string uncertainty = validate(options.odometry.uncertainty);
  if (!uncertainty.empty()) return Status::Error("uncertainty options: " + uncertainty);
  if (options.output_delay_frames < 0 || options.output_delay_frames >= OdometryTrajectory::kMaxDelayFrames) {
    return Status::Error("output delay must be within 0.." + std::to_string(OdometryTrajectory::kMaxDelayFrames - 1) +
                         " frames");
  }
  return Status::Ok();
}

Status OdometrySystem::create(const PinholeCamera& camera, const SystemOptions& options,
                              std::unique_ptr<OdometrySystem>* out) {
  PLUMB_RETURN_IF_ERROR(validate(options));
  const std::string camera_problem = camera.validate();
  if (!camera_problem.empty()) return Status::Error("camera: " + camera_problem);
  // The 8-level pyramid and line detection need room: smaller images are refused, not tracked badly.
  constexpr int kMinTrackedSide = 64;
  if (camera.width < kMinTrackedSide || camera.height < kMinTrackedSide) {
    return Status::Error("camera: image size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                         " is too small to track (at least " + std::to_string(kMinTrackedSide) + " pixels per side)");
  }
  out->reset(new OdometrySystem(camera, options));
  return Status::Ok();
}

OdometrySystem::OdometrySystem(const PinholeCamera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(options),
      mapping_(options.output_delay_frames),
      snapshots_(std::make_unique<runtime::LatestSnapshot<LocalMap>>()),
      relocalizer_(std::make_unique<Relocalizer>(camera, options.odometry)),
      corrections_(std::make_unique<runtime::LatestSnapshot<MapCorrection>>()) {
  tracking_.tracker = std::make_unique<Tracker>(camera, options.odometry);
  mapping_.mapper = std::make_unique<LocalMapper>(camera, options.odometry);
  if (options.splitMapUpdates()) fresh_map_ = std::make_unique<LocalMap>();
}

OdometrySystem::~OdometrySystem() = default;

// ---------------------------------------------------------------------------------------------
// Tracking side

void OdometrySystem::installNewestSnapshot() {
  uint64_t version = 0;
  const LocalMap* snapshot = snapshots_->acquireLatest(&version);
  if (snapshot != nullptr) installSnapshot(*snapshot);
}

void OdometrySystem::installSnapshot(const LocalMap& snapshot) {
  if (snapshot.version <= tracking_.tracker->localMap().version) return;
  // The first snapshot after a new-map request is that map (the mapping side handles frames in
  // order, and the request's frame has been mapped before the next one is tracked).
  if (tracking_.new_map_requested) {
    tracking_.tracker->adoptNewMap(snapshot);
    tracking_.new_map_requested = false;
  } else {
    tracking_.tracker->setLocalMap(snapshot);
  }
}

bool OdometrySystem::canStartMap(const FrameFeatures& features) const {
  int points = 0, lines = 0;
  for (const auto& kp : features.keypoints) points += kp.depth_m > 0;
  if (options_.odometry.tracker.use_lines) {
    for (const auto& line : features.lines) lines += line.has_3d;
  }
  const int needed = options_.odometry.min_initial_points;
  return points >= needed || (points >= needed / 2 && lines >= options_.odometry.min_initial_lines);
}

// The schedule's part of tracking a frame: which map it is tracked against, and whether a keyframe
// request is still pending (no keyframe decision then).
//
// Fixed lag (deterministic and fast, fence->maxFramesAhead() == 0): the update a request of frame k
// asked for is installed when frame k + map_lag_frames is tracked, never earlier or later. A
// threaded run waits there until the map stage has finished frame k completely (keyframe, local
// BA, loop closing and its correction); lock-step has finished it already. Nothing else changes the
// map in between (no keyframe decision while a request is pending; in these schedules the loop
// stage runs on the map stage's thread, right after the keyframe), so every frame is tracked
// against the same map in both schedules: the same bytes, however the threads are timed.
// Split updates (refine_lag_frames M >= 1, map_lag_frames 1): at frame k + 1 the fresh map (the
// fast schedule waits only until the map stage has written it, MapperFence::waitUntilInserted), at
// k + 1 + M the newest whole snapshot, waiting until frame k is mapped completely. That snapshot is
// k's own (or the correction of a loop k closed): a later request k' would have had its fresh map
// installed at k' + 1 <= k + 1 + M, replacing this pending refinement with its own.
bool OdometrySystem::syncWithMapping(MapperFence* fence) {
  const uint64_t frame = tracking_.frames++;
  if (fence != nullptr && fence->maxFramesAhead() > 0) return syncWithNewestSnapshot(*fence);
  if (tracking_.update_pending) {
    if (frame < tracking_.update_due) return true;
    installDueUpdate(fence);
  } else if (tracking_.refinement_pending && frame >= tracking_.refinement_due) {
    if (fence != nullptr && fence->waitUntilMapped(tracking_.refinement_frame + 1)) ++tracking_.mapper_waits;
    installNewestSnapshot();
    tracking_.refinement_pending = false;
  }
  return false;
}

// The update of the request of frame update_frame, at its due frame: the whole update, or the
// fresh map of a split one (and its refinement becomes the pending one).
void OdometrySystem::installDueUpdate(MapperFence* fence) {
  tracking_.update_pending = false;
  const uint64_t frames_mapped = tracking_.update_frame + 1;  // the request's frame included
  if (!options_.splitMapUpdates()) {
    if (fence != nullptr && fence->waitUntilMapped(frames_mapped)) ++tracking_.mapper_waits;
    installNewestSnapshot();
    return;
  }
  if (fence != nullptr && fence->waitUntilInserted(frames_mapped)) ++tracking_.mapper_waits;
  installSnapshot(*fresh_map_);
  tracking_.refinement_pending = !tracking_.update_new_map;  // a new map has no BA to wait for
  tracking_.refinement_frame = tracking_.update_frame;
  tracking_.refinement_due = tracking_.update_frame + 1 + uint64_t(options_.refine_lag_frames);
}

// Real time (fence->maxFramesAhead() > 0): the newest snapshot published so far, with bounded
// staleness on a starved CPU: the tracker runs at most maxFramesAhead() frames past a keyframe it
// asked for before it waits for the mapper to publish it. Without the bound, a lagging map stage
// leaves tracking on an ever older map (no new keyframes while one is pending) and accuracy
// collapses under load. A new map is waited for before the next frame.
bool OdometrySystem::syncWithNewestSnapshot(MapperFence& fence) {
  // Read before installing: a request reported done has its snapshot published already.
  bool request_pending = keyframe_requests_done_.load(std::memory_order_acquire) < tracking_.keyframe_requests;
  if (tracking_.new_map_requested) {
    if (fence.waitUntilMapped(tracking_.frames - 1)) ++tracking_.mapper_waits;
    request_pending = false;
  } else if (request_pending && fence.threaded() && ++tracking_.frames_since_request > fence.maxFramesAhead()) {
    fence.waitForMapper();
    ++tracking_.mapper_waits;
    request_pending = keyframe_requests_done_.load(std::memory_order_acquire) < tracking_.keyframe_requests;
  }
  if (!request_pending) tracking_.frames_since_request = 0;
  installNewestSnapshot();
  return request_pending;
}

// The frame being tracked asked the mapping side for a map update (a keyframe or a new map).
void OdometrySystem::expectMapUpdate(int lag_frames, bool new_map) {
  ++tracking_.keyframe_requests;
  tracking_.update_pending = true;
  tracking_.update_new_map = new_map;
  tracking_.update_frame = tracking_.frames - 1;
  tracking_.update_due = tracking_.update_frame + uint64_t(lag_frames);
}

// The mapping side builds the map from the request (mapFrame), in frame order; the tracker
// restarts from this frame now and adopts the new map with the next frame's snapshot.
void OdometrySystem::requestNewMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                                   const Eigen::Isometry3d& T_world_cam, TrackedFrame* out) {
  tracking_.tracker->fillNewMapRequest(features, sequence, timestamp_s, T_world_cam, &out->request);
  tracking_.tracker->resetAt(features, T_world_cam);
  tracking_.phase = TrackingPhase::kTrack;
  tracking_.lost_streak = 0;
  tracking_.new_map_requested = true;
  out->map_keyframe = true;
  expectMapUpdate(1, true);
  FrameOutput& o = out->output;
  o.state = TrackingState::kOk;
  o.has_pose = true;
  o.T_world_cam = T_world_cam;
  o.keyframe = true;
  o.new_map = true;
}

// The relocalizer's keyframes are written by the mapping side: wait until it is idle.
void OdometrySystem::tryRelocalize(const FrameFeatures& features, MapperFence* fence, TrackedFrame* out) {
  if (fence != nullptr) fence->waitForMapper();
  out->relocalization_attempted = true;
  Eigen::Isometry3d T_world_cam;
  const RelocResult r = relocalizer_->relocalize(features, &T_world_cam);
  if (!r.success) return;
  tracking_.tracker->resetAt(features, T_world_cam);
  tracking_.phase = TrackingPhase::kTrack;
  tracking_.lost_streak = 0;
  FrameOutput& o = out->output;
  o.state = TrackingState::kOk;
  o.has_pose = true;
  o.T_world_cam = T_world_cam;
  o.relocalized = true;
}

void OdometrySystem::relocalizeOrStartSegment(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                                              MapperFence* fence, TrackedFrame* out) {
  tryRelocalize(features, fence, out);
  if (!out->output.has_pose &&
      ++tracking_.lost_streak >= options_.odometry.relocalizer.max_lost_frames_before_new_map &&
      canStartMap(features)) {
    // Relocalization keeps failing: a new map segment from here, at the last known pose.
    requestNewMap(features, sequence, timestamp_s, tracking_.T_world_last_good, out);
  }
}

void OdometrySystem::addLoadedKeyframe(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam, std::size_t n,
                                       const Descriptor256* descriptors, const Eigen::Vector3f* P_cam) {
  relocalizer_->addStoredKeyframe(keyframe_id, T_world_cam, n, descriptors, P_cam);
  ++mapping_.stats.loaded_map_keyframes;
}

void OdometrySystem::beginInLoadedMap(uint32_t first_new_id) {
  mapping_.mapper->setNextKeyframeId(first_new_id);
  tracking_.phase = TrackingPhase::kRelocalizeIntoLoadedMap;
  tracking_.lost_streak = 0;
}

// The relocalized pose is in the loaded map's frame; the local map is empty, so a map starts here
// (a new map segment at that pose) instead of Tracker::resetAt against a map without landmarks.
void OdometrySystem::relocalizeIntoLoadedMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                                             MapperFence* fence, TrackedFrame* out) {
  if (fence != nullptr) fence->waitForMapper();
  out->relocalization_attempted = true;
  Eigen::Isometry3d T_world_cam;
  const RelocResult r = relocalizer_->relocalize(features, &T_world_cam);
  if (!r.success || !canStartMap(features)) return;
  requestNewMap(features, sequence, timestamp_s, T_world_cam, out);
  out->output.relocalized = true;
}

void OdometrySystem::trackAgainstMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                                     bool request_pending, MapperFence* fence, TrackedFrame* out) {
  FrameOutput& o = out->output;
  o.track = tracking_.tracker->track(features, sequence, timestamp_s, request_pending ? nullptr : &out->request);
  o.state = o.track.state;
  if (o.state == TrackingState::kLost) {
    tracking_.phase = TrackingPhase::kRelocalize;
    tracking_.lost_streak = 1;
    tryRelocalize(features, fence, out);
    return;
  }
  o.has_pose = true;
  o.T_world_cam = o.track.T_world_cam;
  const LocalMap& snapshot = tracking_.tracker->localMap();
  out->reference_id = snapshot.reference_keyframe_id;
  out->T_ref_cam = snapshot.T_world_reference.inverse() * o.T_world_cam;
  out->map_keyframe = o.track.keyframe_requested;
  if (out->map_keyframe) expectMapUpdate(options_.map_lag_frames, false);
}

void OdometrySystem::trackFeatures(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                                   MapperFence* fence, TrackedFrame* out) {
  const auto start = std::chrono::steady_clock::now();
  const bool request_pending = syncWithMapping(fence);
  const LocalMap& installed = tracking_.tracker->localMap();
  if (installed.loop_corrections != tracking_.loop_corrections_seen) {
    // A new segment restarts the count at 0 (and is announced as a new map); only an increase is a jump.
    tracking_.loop_correction_unannounced |= installed.loop_corrections > tracking_.loop_corrections_seen;
    tracking_.loop_corrections_seen = installed.loop_corrections;
  }
  FrameOutput& o = out->output;
  o = FrameOutput{};
  o.sequence = sequence;
  o.timestamp_s = timestamp_s;
  out->reference_id = 0;
  out->T_ref_cam = Eigen::Isometry3d::Identity();
  out->map_keyframe = false;
  out->relocalization_attempted = false;

  switch (tracking_.phase) {
    case TrackingPhase::kStartMap:
      if (canStartMap(features)) requestNewMap(features, sequence, timestamp_s, tracking_.T_world_last_good, out);
      break;
    case TrackingPhase::kRelocalizeIntoLoadedMap:
      relocalizeIntoLoadedMap(features, sequence, timestamp_s, fence, out);
      break;
    case TrackingPhase::kRelocalize:
      relocalizeOrStartSegment(features, sequence, timestamp_s, fence, out);
      break;
    case TrackingPhase::kTrack:
      trackAgainstMap(features, sequence, timestamp_s, request_pending, fence, out);
      break;
  }
  // Once a map exists (or a loaded one is awaited) a frame without a pose is lost.
  if (!o.has_pose && tracking_.phase != TrackingPhase::kStartMap) o.state = TrackingState::kLost;
  if (o.has_pose) tracking_.T_world_last_good = o.T_world_cam;
  if (o.has_pose && tracking_.loop_correction_unannounced) {
    o.loop_corrected = true;
    tracking_.loop_correction_unannounced = false;
  }
  o.track_ms = millisecondsSince(start);
}

// ---------------------------------------------------------------------------------------------
// Mapping side

void OdometrySystem::insertKeyframe(const KeyframeRequest& request, bool split, MapperFence* fence) {
  LocalMapper& mapper = *mapping_.mapper;
  InsertResult inserted;
  bool refined = true;
  if (split) {
    inserted = mapper.addKeyframe(request, fresh_map_.get());
    // The tracker may go on with the next frame now, against the fresh map, while the BA runs.
    if (fence != nullptr) fence->insertionPublished();
    refined = mapper.refineKeyframe(&inserted);
  } else {
    inserted = mapper.insertKeyframe(request);
  }
  mapping_.output.insert = inserted;
  if (!inserted.inserted) return;
  const LocalMap& snapshot = mapper.localMap();
  // Copied into the channel's preallocated buffer; the tracker installs it when it is due. A new
  // map's split update is its fresh map alone.
  if (refined) {
    snapshots_->writeBuffer() = snapshot;
    snapshots_->publish(snapshot.version);
  }
  relocalizer_->addKeyframe(inserted.keyframe_id, request.T_world_cam, request.features);
  // Stored keyframes follow local BA's refinements while they are in the map.
  for (const LocalMapKeyframe& kf : snapshot.keyframes) relocalizer_->updatePose(kf.id, kf.T_world_cam);
  mapping_.output.keyframe = true;
}

bool OdometrySystem::applyLoopCorrection() {
  uint64_t version = 0;
  const MapCorrection* correction = corrections_->acquireLatest(&version);
  if (correction == nullptr || version <= mapping_.correction_version) return false;
  mapping_.correction_version = version;
  if (!mapping_.mapper->applyCorrection(*correction)) {
    ++mapping_.stats.loop_corrections_stale;
    return false;
  }
  ++mapping_.stats.loop_corrections_applied;
  mapping_.last_correction = *correction;
  if (mapping_.applied_corrections.size() < kMaxRecordedCorrections)
    mapping_.applied_corrections.push_back(mapping_.mapper->lastCorrection());
  const LocalMap& snapshot = mapping_.mapper->localMap();
  snapshots_->writeBuffer() = snapshot;
  snapshots_->publish(snapshot.version);
  for (const LocalMapKeyframe& kf : snapshot.keyframes) relocalizer_->updatePose(kf.id, kf.T_world_cam);
  return true;
}

const FrameOutput& OdometrySystem::mapFrame(const TrackedFrame& tracked, MapperFence* fence) {
  // A loop correction first: this frame's keyframe (if any) is inserted into the corrected map.
  applyLoopCorrection();
  // Real time tracks on the newest whole update (syncWithNewestSnapshot): no split there.
  const bool split = options_.splitMapUpdates() && (fence == nullptr || fence->maxFramesAhead() == 0);
  mapping_.output = tracked.output;
  uint32_t reference_id = tracked.reference_id;
  Eigen::Isometry3d T_ref_cam = tracked.T_ref_cam;
  if (tracked.map_keyframe) {
    const auto map_start = std::chrono::steady_clock::now();
    insertKeyframe(tracked.request, split, fence);
    keyframe_requests_done_.fetch_add(1, std::memory_order_release);
    mapping_.output.map_ms = millisecondsSince(map_start);
    if (mapping_.output.keyframe) {
      reference_id = mapping_.output.insert.keyframe_id;
      T_ref_cam = Eigen::Isometry3d::Identity();
    }
  }
  recordOutput(tracked);
  const LocalMap& world = mapping_.mapper->localMap();
  mapping_.trajectory.setWorld(mapping_.stats.loop_corrections_applied, world.segment, world.loop_corrections,
                               world.T_loop_corrections);
  mapping_.stats.output_overflows += !mapping_.trajectory.push(mapping_.output.sequence, mapping_.output.timestamp_s, mapping_.output.has_pose, mapping_.output.T_world_cam, reference_id,
                   T_ref_cam);
  return mapping_.output;
}

const FrameOutput& OdometrySystem::mapDroppedFrame(uint64_t sequence, double timestamp_s) {
  mapping_.output = FrameOutput{};
  mapping_.output.sequence = sequence;
  mapping_.output.timestamp_s = timestamp_s;
  mapping_.output.dropped = true;
  mapping_.stats.output_overflows += !mapping_.trajectory.pushDropped(sequence, timestamp_s);
  return mapping_.output;
}

void OdometrySystem::recordOutput(const TrackedFrame& tracked) {
  ++mapping_.stats.frames;
  mapping_.stats.relocalization_attempts += tracked.relocalization_attempted;
  mapping_.stats.relocalizations += mapping_.output.relocalized;
  if (mapping_.output.relocalized && mapping_.output.new_map && mapping_.stats.loaded_map_relocalized_frame < 0) {
    mapping_.stats.loaded_map_relocalized_frame = int64_t(mapping_.stats.frames) - 1;  // frames counts this one
  }
  mapping_.stats.segments += mapping_.output.new_map;
  mapping_.stats.keyframes += mapping_.output.keyframe;
  if (mapping_.output.track.used_motion_fallback) ++mapping_.stats.frames_motion_fallback;
  if (mapping_.output.state == TrackingState::kNotInitialized && !mapping_.output.has_pose) {
    ++mapping_.stats.frames_not_initialized;
  } else if (!mapping_.output.has_pose) {
    ++mapping_.stats.frames_lost;
  } else if (mapping_.output.state == TrackingState::kWeak) {
    ++mapping_.stats.frames_weak;
  } else {
    ++mapping_.stats.frames_ok;
  }
}

}  // namespace plumb
