#include "pipeline/odometry/tracker.h"


#include <cmath>
#include <limits>

#include "pipeline/odometry/keyframe_policy.h"
#include "pipeline/odometry/tracker_rolling_shutter.h"
#include "solver/noise_model.h"
#include "solver/se3.h"

namespace plumb {

const char* toString(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized: return "not_initialized";
    case TrackingState::kOk: return "ok";
    case TrackingState::kWeak: return "weak";
    case TrackingState::kLost: return "lost";
  }
  return "?";
}

namespace {

MatcherOptions withRadius(MatcherOptions options, float radius_px) {
  options.points.search_radius_px = radius_px;
  return options;
}

}  // namespace

Tracker::Tracker(const PinholeCamera& camera, const OdometryOptions& options)
    : camera_(camera),
      options_(options),
      matcher_(options.matcher),
      wide_matcher_(withRadius(options.matcher, options.tracker.wide_search_radius_px)),
      local_matcher_(withRadius(options.matcher, options.tracker.local_map_search_radius_px)),
      compensated_frame_(1),
      b_(std::make_unique<Buffers>()) {
  intrinsics_ = CameraIntrinsics{camera.fx, camera.fy, camera.cx, camera.cy, camera.fx * camera.baseline_m};
  pose_options_.chi2 = options.tracker.chi2;
  pose_options_.rounds = options.tracker.pose_rounds;
  pose_options_.iterations_per_round = options.tracker.pose_iterations_per_round;
  pose_options_.step_tolerance = options.tracker.pose_step_tolerance;
  for (int octave = 0; octave < kPyramidLevels; ++octave) {
    mono_point_information_[octave] = monoPointInformation(options.extractor.noise, octave);
    line_sample_information_[octave] = lineSampleInformation(options.extractor.noise, octave);
  }
  local_map_ = &b_->local_map;
  local_map_->clear();
}

Tracker::~Tracker() = default;

void Tracker::setLocalMap(const LocalMap& local_map) {
  // Corrections only make sense within one map segment (a new segment restarts with resetAt).
  const bool same_map = local_map_->version != 0 && local_map.segment == local_map_->segment;
  if (has_last_frame_ && same_map && local_map.loop_corrections != local_map_->loop_corrections) {
    followLoopCorrection(local_map.T_loop_corrections * local_map_->T_loop_corrections.inverse());
  }
  *local_map_ = local_map;
  b_->point_visible.fill(0);
  b_->point_found.fill(0);
  b_->line_visible.fill(0);
  b_->line_found.fill(0);
  // The landmark slots may have been reused by the mapper: associations of the last frame that
  // name a landmark keep their 3D point but lose the (now possibly stale) local index.
  for (auto& a : b_->last_points) a.local_index = -1;
  for (auto& a : b_->last_lines) a.local_index = -1;
  if (has_last_frame_ && same_map) followMapCorrections();
}

void Tracker::adoptNewMap(const LocalMap& local_map) {
  setLocalMap(local_map);
  last_reference_id_ = local_map_->reference_keyframe_id;
  T_world_last_reference_ = local_map_->T_world_reference;
}

void Tracker::reset() {
  state_ = TrackingState::kNotInitialized;
  has_last_frame_ = false;
  has_velocity_ = false;
  frames_since_keyframe_ = 0;
  local_map_->clear();
}

void Tracker::resetAt(const FrameFeatures& frame, const Eigen::Isometry3d& T_world_cam) {
  clearAssociations(frame);
  rememberLastFrame(frame, T_world_cam);
  last_sequence_ = kUnknownSequence;
  last_timestamp_s_ = std::numeric_limits<double>::quiet_NaN();  // the next velocity has no time span
  has_velocity_ = false;
  state_ = TrackingState::kOk;
  frames_since_keyframe_ = 0;
}

TrackResult Tracker::track(const FrameFeatures& input, uint64_t sequence, double timestamp_s,
                           KeyframeRequest* request) {
  const FrameFeatures* features = &input;
  if (camera_.rolling_shutter_readout_s > 0 && has_velocity_ && velocity_dt_s_ > 0) {
    compensated_frame_[0].copyFrom(input);  // the used entries only, not all ~290 kB of capacity
    compensateRollingShutter(camera_, camera_.rolling_shutter_readout_s,
                             logSE3(velocity_cur_last_) / velocity_dt_s_, &compensated_frame_[0]);
    features = &compensated_frame_[0];
  }
  const FrameFeatures& frame = *features;
  TrackResult result;
  ++frame_stamp_;
  if (!has_last_frame_) {
    result.state = state_;
    return result;
  }
  const Eigen::Isometry3d T_cam_world_last = T_world_last_.inverse();

  // 1. Match the last frame: constant velocity, then a wide window, then zero motion.
  Eigen::Isometry3d T_cam_world_pred =
      has_velocity_ ? Eigen::Isometry3d(velocity_cur_last_ * T_cam_world_last) : T_cam_world_last;
  clearAssociations(frame);
  int matches = matchLastFrame(frame, T_cam_world_pred, matcher_);
  if (matches < options_.tracker.min_frame_matches) {
    result.used_motion_fallback = true;
    clearAssociations(frame);
    matches = matchLastFrame(frame, T_cam_world_pred, wide_matcher_);
    if (matches < options_.tracker.min_frame_matches && has_velocity_) {
      T_cam_world_pred = T_cam_world_last;
      clearAssociations(frame);
      matches = matchLastFrame(frame, T_cam_world_pred, wide_matcher_);
    }
  }
  result.frame_matches = matches;

  // 2. Pose from the last frame's matches, optimised from the prediction. (The lean towards the
  // start once seen here was the start's drift off SO(3) surviving the optimisation; optimizePose
  // now projects its start onto SO(3), so the converged pose no longer depends on the start.)
  Eigen::Isometry3d T_cam_world = T_cam_world_pred;
  if (matches >= 6) {
    // Only its pose and inliers are used (for the local-map search): no covariance.
    const PoseResult pose = optimizeAndPrune(frame, T_cam_world_pred, &result, /*final_pose=*/false);
    T_cam_world = pose.T_cam_world;
  }

  // 3. Local map: more matches, optimise again with everything.
  result.local_map_matches = matchLocalMap(frame, T_cam_world);
  PoseResult final_pose;
  if (result.frame_matches + result.local_map_matches >= 6) {
    final_pose = optimizeAndPrune(frame, T_cam_world, &result);
    T_cam_world = final_pose.T_cam_world;
  }
  const int inliers = result.point_inliers + result.line_inliers;
  if (inliers >= options_.tracker.min_inliers_ok) {
    state_ = TrackingState::kOk;
  } else if (inliers >= options_.tracker.min_inliers_weak) {
    state_ = TrackingState::kWeak;
  } else {
    state_ = TrackingState::kLost;
  }
  result.state = state_;
  const Eigen::Isometry3d T_world_cam = T_cam_world.inverse();
  result.T_world_cam = T_world_cam;
  if (state_ == TrackingState::kLost) {
    // Keep the last good frame: relocalization takes over; the velocity is meaningless now.
    has_velocity_ = false;
    return result;
  }

  // Visibility statistics for culling (found = matched as an inlier).
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    const PointAssociation& a = b_->points[k];
    if (a.valid && a.local_index >= 0) ++b_->point_found[a.local_index];
  }
  for (std::size_t k = 0; k < frame.lines.size(); ++k) {
    const LineAssociation& a = b_->lines[k];
    if (a.valid && a.local_index >= 0) ++b_->line_found[a.local_index];
  }

  // T_world_last_ followed every map change since the last frame (followMapCorrections).
  result.has_previous = std::isfinite(last_timestamp_s_);
  result.previous_timestamp_s = last_timestamp_s_;
  result.T_world_previous = T_world_last_;
  velocity_cur_last_ = T_cam_world * T_world_last_;
  velocity_dt_s_ = timestamp_s - last_timestamp_s_;
  has_velocity_ = true;
  const Vector6d twist_per_s = velocity_dt_s_ > 0 ? Vector6d(logSE3(velocity_cur_last_) / velocity_dt_s_) : Vector6d::Zero();
  publishCovariance(final_pose, twist_per_s, &result);
  ++frames_since_keyframe_;
  if (request != nullptr && keyframeNeeded(frame, result)) {
    fillKeyframeRequest(frame, sequence, timestamp_s, T_world_cam, request);
    request->twist_per_s = twist_per_s;
    result.keyframe_requested = true;
    frames_since_keyframe_ = 0;
  }
  rememberLastFrame(frame, T_world_cam);
  last_sequence_ = sequence;
  last_timestamp_s_ = timestamp_s;
  return result;
}

bool Tracker::keyframeNeeded(const FrameFeatures& frame, const TrackResult& result) const {
  KeyframeEvidence e;
  e.frames_since_keyframe = frames_since_keyframe_;
  e.inliers = result.point_inliers + result.line_inliers;
  e.landmark_inliers = result.landmark_inliers;
  e.reference_tracked = local_map_->reference_tracked_landmarks;
  e.keyframes_in_map = local_map_->keyframes_in_map;
  e.weak = result.state == TrackingState::kWeak;
  const float close_depth = options_.keyframes.close_depth_baselines * float(camera_.baseline_m);
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    const KeypointObservation& kp = frame.keypoints[k];
    if (kp.depth_m <= 0 || kp.depth_m > close_depth) continue;
    if (b_->points[k].valid && b_->points[k].landmark.id != 0) {
      ++e.tracked_close;
    } else {
      ++e.untracked_close;
    }
  }
  return needNewKeyframe(options_.keyframes, e);
}

void Tracker::rememberLastFrame(const FrameFeatures& frame, const Eigen::Isometry3d& T_world_cam) {
  b_->last_frame.copyFrom(frame);
  T_world_last_ = T_world_cam;
  has_last_frame_ = true;
  last_reference_id_ = local_map_->reference_keyframe_id;
  T_world_last_reference_ = local_map_->T_world_reference;
  const Eigen::Matrix3d R = T_world_cam.linear();
  const Eigen::Vector3d t = T_world_cam.translation();
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    PointAssociation& last = b_->last_points[k];
    const PointAssociation& cur = b_->points[k];
    if (cur.valid && cur.landmark.id != 0) {
      last = cur;  // a landmark keeps its optimised position
      continue;
    }
    last = PointAssociation{};
    const KeypointObservation& kp = frame.keypoints[k];
    if (kp.depth_m > 0) {
      last.valid = true;
      last.P_world = R * kp.P_cam.cast<double>() + t;
    }
  }
  for (std::size_t k = 0; k < frame.lines.size(); ++k) {
    LineAssociation& last = b_->last_lines[k];
    const LineAssociation& cur = b_->lines[k];
    if (cur.valid && cur.landmark.id != 0) {
      last = cur;
      continue;
    }
    last = LineAssociation{};
    const LineObservation& line = frame.lines[k];
    if (line.has_3d && line.num_samples > 0) {
      last.valid = true;
      last.num_samples = line.num_samples;
      for (int s = 0; s < line.num_samples; ++s) {
        last.samples_world[s] = R * line.sample_P_cam[s].cast<double>() + t;
      }
    }
  }
}

void Tracker::fillNewMapRequest(const FrameFeatures& frame, uint64_t sequence, double timestamp_s,
                                const Eigen::Isometry3d& T_world_cam, KeyframeRequest* request) const {
  request->start_new_map = true;
  request->frame_sequence = sequence;
  request->timestamp_s = timestamp_s;
  request->twist_per_s.setZero();
  request->T_world_cam = T_world_cam;
  request->local_map_version = 0;
  request->features.copyFrom(frame);  // the used entries only (a keyframe's copy, ~290 kB of capacity)
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) request->keypoint_landmark[k] = LandmarkRef{};
  for (std::size_t k = 0; k < frame.lines.size(); ++k) request->line_landmark[k] = LandmarkRef{};
  request->point_visibility.clear();
  request->line_visibility.clear();
}

void Tracker::fillKeyframeRequest(const FrameFeatures& frame, uint64_t sequence, double timestamp_s,
                                  const Eigen::Isometry3d& T_world_cam, KeyframeRequest* request) {
  fillNewMapRequest(frame, sequence, timestamp_s, T_world_cam, request);
  request->start_new_map = false;
  request->local_map_version = local_map_->version;
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    if (b_->points[k].valid) request->keypoint_landmark[k] = b_->points[k].landmark;
  }
  for (std::size_t k = 0; k < frame.lines.size(); ++k) {
    if (b_->lines[k].valid) request->line_landmark[k] = b_->lines[k].landmark;
  }
  for (std::size_t i = 0; i < local_map_->points.size(); ++i) {
    if (b_->point_visible[i] == 0) continue;
    (void)request->point_visibility.push_back(
        LandmarkVisibility{local_map_->points[i].ref, b_->point_visible[i], b_->point_found[i]});
  }
  for (std::size_t i = 0; i < local_map_->lines.size(); ++i) {
    if (b_->line_visible[i] == 0) continue;
    (void)request->line_visibility.push_back(
        LandmarkVisibility{local_map_->lines[i].ref, b_->line_visible[i], b_->line_found[i]});
  }
  // Delivered: counting restarts so no frame is reported twice.
  b_->point_visible.fill(0);
  b_->point_found.fill(0);
  b_->line_visible.fill(0);
  b_->line_found.fill(0);
}

}  // namespace plumb
