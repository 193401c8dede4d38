#include "pipeline/odometry/odometry_system.h"

#include <chrono>

namespace plumb {

namespace {

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

OdometrySystem::OdometrySystem(const PinholeCamera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(options),
      extractor_(std::make_unique<FeatureExtractor>(camera, options.odometry.extractor)),
      tracker_(std::make_unique<Tracker>(camera, options.odometry)),
      mapper_(std::make_unique<LocalMapper>(camera, options.odometry)),
      relocalizer_(std::make_unique<Relocalizer>(camera, options.odometry)),
      features_(std::make_unique<FrameFeatures>()),
      tracked_(std::make_unique<TrackedFrame>()),
      snapshots_(std::make_unique<runtime::LatestSnapshot<LocalMap>>()),
      trajectory_(options.output_delay_frames) {}

OdometrySystem::~OdometrySystem() = default;

const FrameOutput& OdometrySystem::processImage(const RgbdImage& image) {
  const auto start = std::chrono::steady_clock::now();
  if (!extractor_->extract(image, *features_)) {
    ++stats_.extraction_failures;
    features_->clear();
  }
  const double extract_ms = millisecondsSince(start);
  processFeatures(*features_, image.sequence, image.timestamp_s);
  output_.extract_ms = extract_ms;
  return output_;
}

const FrameOutput& OdometrySystem::processFeatures(const FrameFeatures& features, uint64_t sequence,
                                                   double timestamp_s) {
  trackFeatures(features, sequence, timestamp_s, nullptr, tracked_.get());
  return mapFrame(*tracked_);
}

// ---------------------------------------------------------------------------------------------
// Tracking side

void OdometrySystem::installNewestSnapshot() {
  uint64_t version = 0;
  const LocalMap* snapshot = snapshots_->acquireLatest(&version);
  // Older than what the tracker has: a map start installed a newer one directly (startMap).
  if (snapshot != nullptr && snapshot->version > tracker_->localMap().version) tracker_->setLocalMap(*snapshot);
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

// Synchronous with the mapper (after the fence): the next frame must be tracked against the new
// map, and a map start is rare (first frame, relocalization failing for many frames).
void OdometrySystem::startMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                              const Eigen::Isometry3d& T_world_cam, MapperFence* fence, TrackedFrame* out) {
  if (fence != nullptr) fence->waitForMapper();
  KeyframeRequest& request = out->request;
  tracker_->fillNewMapRequest(features, sequence, timestamp_s, T_world_cam, &request);
  const InsertResult inserted = mapper_->insertKeyframe(request);
  tracker_->setLocalMap(mapper_->localMap());
  tracker_->resetAt(features, T_world_cam);
  relocalizer_->addKeyframe(inserted.keyframe_id, T_world_cam, features);
  map_started_ = true;
  lost_ = false;
  lost_streak_ = 0;
  FrameOutput& o = out->output;
  o.state = TrackingState::kOk;
  o.has_pose = true;
  o.T_world_cam = T_world_cam;
  o.keyframe = true;
  o.new_map = true;
  o.insert = inserted;
  out->reference_id = inserted.keyframe_id;
}

// The relocalizer's keyframes are written by the mapping side: wait until it is idle.
void OdometrySystem::tryRelocalize(const FrameFeatures& features, MapperFence* fence, TrackedFrame* out) {
  if (fence != nullptr) fence->waitForMapper();
  out->relocalization_attempted = true;
  Eigen::Isometry3d T_world_cam;
  const RelocResult r = relocalizer_->relocalize(features, &T_world_cam);
  if (!r.success) return;
  tracker_->resetAt(features, T_world_cam);
  lost_ = false;
  lost_streak_ = 0;
  FrameOutput& o = out->output;
  o.state = TrackingState::kOk;
  o.has_pose = true;
  o.T_world_cam = T_world_cam;
  o.relocalized = true;
}

void OdometrySystem::trackFeatures(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                                   MapperFence* fence, TrackedFrame* out) {
  const auto start = std::chrono::steady_clock::now();
  // Read before installing: a request reported done has its snapshot published already.
  const bool request_pending = keyframe_requests_done_.load(std::memory_order_acquire) < keyframe_requests_;
  installNewestSnapshot();
  FrameOutput& o = out->output;
  o = FrameOutput{};
  o.sequence = sequence;
  o.timestamp_s = timestamp_s;
  out->reference_id = 0;
  out->T_ref_cam = Eigen::Isometry3d::Identity();
  out->map_keyframe = false;
  out->relocalization_attempted = false;

  if (!map_started_) {
    if (canStartMap(features)) startMap(features, sequence, timestamp_s, T_world_last_good_, fence, out);
  } else if (lost_) {
    tryRelocalize(features, fence, out);
    if (!o.has_pose && ++lost_streak_ >= options_.odometry.relocalizer.max_lost_frames_before_new_map &&
        canStartMap(features)) {
      // Relocalization keeps failing: a new map segment from here, at the last known pose.
      startMap(features, sequence, timestamp_s, T_world_last_good_, fence, out);
    }
  } else {
    o.track = tracker_->track(features, sequence, timestamp_s, request_pending ? nullptr : &out->request);
    o.state = o.track.state;
    if (o.state == TrackingState::kLost) {
      lost_ = true;
      lost_streak_ = 1;
      tryRelocalize(features, fence, out);
    } else {
      o.has_pose = true;
      o.T_world_cam = o.track.T_world_cam;
      const LocalMap& snapshot = tracker_->localMap();
      out->reference_id = snapshot.reference_keyframe_id;
      out->T_ref_cam = snapshot.T_world_reference.inverse() * o.T_world_cam;
      out->map_keyframe = o.track.keyframe_requested;
      keyframe_requests_ += out->map_keyframe;
    }
  }
  if (!o.has_pose && map_started_) o.state = TrackingState::kLost;
  if (o.has_pose) T_world_last_good_ = o.T_world_cam;
  o.track_ms = millisecondsSince(start);
}

// ---------------------------------------------------------------------------------------------
// Mapping side

void OdometrySystem::insertKeyframe(const KeyframeRequest& request) {
  const InsertResult inserted = mapper_->insertKeyframe(request);
  output_.insert = inserted;
  if (!inserted.inserted) return;
  const LocalMap& snapshot = mapper_->localMap();
  // Copied into the channel's preallocated buffer; the tracker installs it before its next frame.
  snapshots_->writeBuffer() = snapshot;
  snapshots_->publish(snapshot.version);
  relocalizer_->addKeyframe(inserted.keyframe_id, request.T_world_cam, request.features);
  // Stored keyframes follow local BA's refinements while they are in the map.
  for (const LocalMapKeyframe& kf : snapshot.keyframes) relocalizer_->updatePose(kf.id, kf.T_world_cam);
  output_.keyframe = true;
}

const FrameOutput& OdometrySystem::mapFrame(const TrackedFrame& tracked) {
  output_ = tracked.output;
  uint32_t reference_id = tracked.reference_id;
  Eigen::Isometry3d T_ref_cam = tracked.T_ref_cam;
  if (tracked.map_keyframe) {
    const auto map_start = std::chrono::steady_clock::now();
    insertKeyframe(tracked.request);
    keyframe_requests_done_.fetch_add(1, std::memory_order_release);
    output_.map_ms = millisecondsSince(map_start);
    if (output_.keyframe) {
      reference_id = output_.insert.keyframe_id;
      T_ref_cam = Eigen::Isometry3d::Identity();
    }
  }
  recordOutput(tracked);
  trajectory_.push(output_.sequence, output_.timestamp_s, output_.has_pose, output_.T_world_cam, reference_id,
                   T_ref_cam);
  return output_;
}

const FrameOutput& OdometrySystem::mapDroppedFrame(uint64_t sequence, double timestamp_s) {
  output_ = FrameOutput{};
  output_.sequence = sequence;
  output_.timestamp_s = timestamp_s;
  output_.dropped = true;
  trajectory_.pushDropped(sequence, timestamp_s);
  return output_;
}

void OdometrySystem::recordOutput(const TrackedFrame& tracked) {
  ++stats_.frames;
  stats_.relocalization_attempts += tracked.relocalization_attempted;
  stats_.relocalizations += output_.relocalized;
  stats_.segments += output_.new_map;
  stats_.keyframes += output_.keyframe;
  if (output_.track.used_motion_fallback) ++stats_.frames_motion_fallback;
  if (output_.state == TrackingState::kNotInitialized && !output_.has_pose) {
    ++stats_.frames_not_initialized;
  } else if (!output_.has_pose) {
    ++stats_.frames_lost;
  } else if (output_.state == TrackingState::kWeak) {
    ++stats_.frames_weak;
  } else {
    ++stats_.frames_ok;
  }
}

}  // namespace plumb
