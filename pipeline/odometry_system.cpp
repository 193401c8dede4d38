#include "pipeline/odometry_system.h"

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
      request_(std::make_unique<KeyframeRequest>()),
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

bool OdometrySystem::canStartMap(const FrameFeatures& features) const {
  int points = 0, lines = 0;
  for (const auto& kp : features.keypoints) points += kp.depth_m > 0;
  if (options_.odometry.tracker.use_lines) {
    for (const auto& line : features.lines) lines += line.has_3d;
  }
  const int needed = options_.odometry.min_initial_points;
  return points >= needed || (points >= needed / 2 && lines >= options_.odometry.min_initial_lines);
}

void OdometrySystem::startMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                              const Eigen::Isometry3d& T_world_cam) {
  tracker_->fillNewMapRequest(features, sequence, timestamp_s, T_world_cam, request_.get());
  const InsertResult inserted = mapper_->insertKeyframe(*request_);
  tracker_->setLocalMap(mapper_->localMap());
  tracker_->resetAt(features, T_world_cam);
  relocalizer_->addKeyframe(inserted.keyframe_id, T_world_cam, features);
  map_started_ = true;
  lost_ = false;
  lost_streak_ = 0;
  ++stats_.segments;
  ++stats_.keyframes;
  output_.state = TrackingState::kOk;
  output_.has_pose = true;
  output_.T_world_cam = T_world_cam;
  output_.keyframe = true;
  output_.new_map = true;
  output_.insert = inserted;
}

void OdometrySystem::insertKeyframe() {
  const InsertResult inserted = mapper_->insertKeyframe(*request_);
  output_.insert = inserted;
  if (!inserted.inserted) return;
  const LocalMap& snapshot = mapper_->localMap();
  tracker_->setLocalMap(snapshot);
  relocalizer_->addKeyframe(inserted.keyframe_id, request_->T_world_cam, request_->features);
  // Stored keyframes follow local BA's refinements while they are in the map.
  for (const LocalMapKeyframe& kf : snapshot.keyframes) relocalizer_->updatePose(kf.id, kf.T_world_cam);
  output_.keyframe = true;
  ++stats_.keyframes;
}

void OdometrySystem::tryRelocalize(const FrameFeatures& features) {
  ++stats_.relocalization_attempts;
  Eigen::Isometry3d T_world_cam;
  const RelocResult r = relocalizer_->relocalize(features, &T_world_cam);
  if (!r.success) return;
  tracker_->resetAt(features, T_world_cam);
  lost_ = false;
  lost_streak_ = 0;
  ++stats_.relocalizations;
  output_.state = TrackingState::kOk;
  output_.has_pose = true;
  output_.T_world_cam = T_world_cam;
  output_.relocalized = true;
}

const FrameOutput& OdometrySystem::processFeatures(const FrameFeatures& features, uint64_t sequence,
                                                   double timestamp_s) {
  const auto start = std::chrono::steady_clock::now();
  output_ = FrameOutput{};
  output_.sequence = sequence;
  output_.timestamp_s = timestamp_s;
  ++stats_.frames;
  uint32_t reference_id = 0;
  Eigen::Isometry3d T_ref_cam = Eigen::Isometry3d::Identity();
  double map_ms = 0;

  if (!map_started_) {
    if (canStartMap(features)) {
      startMap(features, sequence, timestamp_s, T_world_last_good_);
      reference_id = output_.insert.keyframe_id;
    }
  } else if (lost_) {
    tryRelocalize(features);
    if (!output_.has_pose && ++lost_streak_ >= options_.odometry.relocalizer.max_lost_frames_before_new_map &&
        canStartMap(features)) {
      // Relocalization keeps failing: a new map segment from here, at the last known pose.
      startMap(features, sequence, timestamp_s, T_world_last_good_);
      reference_id = output_.insert.keyframe_id;
    }
  } else {
    output_.track = tracker_->track(features, sequence, timestamp_s, request_.get());
    output_.state = output_.track.state;
    if (output_.state == TrackingState::kLost) {
      lost_ = true;
      lost_streak_ = 1;
      tryRelocalize(features);
    } else {
      output_.has_pose = true;
      output_.T_world_cam = output_.track.T_world_cam;
      const LocalMap& snapshot = tracker_->localMap();
      reference_id = snapshot.reference_keyframe_id;
      T_ref_cam = snapshot.T_world_reference.inverse() * output_.T_world_cam;
      if (output_.track.keyframe_requested) {
        const auto map_start = std::chrono::steady_clock::now();
        insertKeyframe();
        map_ms = millisecondsSince(map_start);
        if (output_.keyframe) {
          reference_id = output_.insert.keyframe_id;
          T_ref_cam = Eigen::Isometry3d::Identity();
        }
      }
    }
  }
  if (!output_.has_pose && map_started_) output_.state = TrackingState::kLost;
  recordOutput();
  trajectory_.push(sequence, timestamp_s, output_.has_pose, output_.T_world_cam, reference_id, T_ref_cam);
  output_.map_ms = map_ms;
  output_.track_ms = millisecondsSince(start) - map_ms;
  return output_;
}

void OdometrySystem::recordOutput() {
  if (output_.has_pose) T_world_last_good_ = output_.T_world_cam;
  if (output_.track.used_motion_fallback) ++stats_.frames_motion_fallback;
  if (!map_started_) {
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
