#include "pipeline/odometry/local_mapper.h"

#include <algorithm>

#include "pipeline/odometry/map_line_geometry.h"
#include "solver/noise_model.h"

namespace plumb {

LocalMapper::LocalMapper(const PinholeCamera& camera, const OdometryOptions& options)
    : camera_(camera),
      options_(options),
      s_(std::make_unique<Scratch>()),
      local_map_(std::make_unique<LocalMap>()) {
  intrinsics_ = CameraIntrinsics{camera.fx, camera.fy, camera.cx, camera.cy, camera.fx * camera.baseline_m};
  const LocalMapperOptions& m = options.mapper;
  ba_options_.max_iterations = m.ba_iterations;
  ba_options_.function_tolerance = m.ba_function_tolerance;
  ba_options_.chi2 = m.chi2;
  const int max_keyframes = m.ba_optimised_keyframes + m.ba_fixed_keyframes;
  const int max_observations = m.max_ba_landmarks * 8;
  ba_.reserve(max_keyframes, m.max_ba_landmarks, max_observations);
  ba_.setCamera(intrinsics_);
  ba_observations_.resize(std::size_t(max_observations));
  local_map_->clear();
}

LocalMapper::~LocalMapper() = default;

void LocalMapper::retireKeyframe(int kf_slot) {
  const Keyframe& kf = map_.keyframe(kf_slot);
  RetiredKeyframe r;
  r.id = kf.id;
  r.frame_sequence = kf.frame_sequence;
  r.timestamp_s = kf.timestamp_s;
  r.T_world_cam = kf.T_world_cam;
  r.covariance = kf.covariance;
  r.covariance_valid = kf.covariance_valid;
  r.uncertainty = kf.uncertainty;
  // retired_ is drained by the caller after every insertion; when it is not, the oldest report
  // is the one dropped (the output is a courtesy, the map must stay bounded).
  if (retired_.full()) {
    for (std::size_t i = 1; i < retired_.size(); ++i) retired_[i - 1] = retired_[i];
    retired_.pop_back();
  }
  (void)retired_.push_back(r);
  map_.removeKeyframe(kf_slot);
}

void LocalMapper::retireAll() {
  for (int slot = map_.oldestKeyframeSlot(); slot >= 0; slot = map_.oldestKeyframeSlot()) retireKeyframe(slot);
  local_map_->clear();
}

InsertResult LocalMapper::insertKeyframe(const KeyframeRequest& request) {
  InsertResult result = addUnrefined(request);
  (void)refineKeyframe(&result);
  return result;
}

InsertResult LocalMapper::addKeyframe(const KeyframeRequest& request, LocalMap* fresh) {
  InsertResult result = addUnrefined(request);
  if (!result.inserted) return result;
  // The landmarks the tracker's counts (applyVisibility) already condemn leave before the fresh
  // map is made, not only after the BA (ORB-SLAM culls before its local BA too): frames tracked
  // against the fresh map then do not match them. Measured on head250 over six start frames at
  // M = 1: mean ATE +6.5 % over the unsplit update instead of +9 % without this cull.
  if (!unrefined_new_map_) cullLandmarks(result.keyframe_id);
  buildSnapshot(unrefined_slot_, fresh);
  return result;
}

bool LocalMapper::refineKeyframe(InsertResult* result) {
  const int kf_slot = unrefined_slot_;
  if (kf_slot < 0) return false;
  unrefined_slot_ = -1;
  const bool refine = !unrefined_new_map_;  // a new map has nothing to adjust yet
  if (refine) {
    runLocalBa(kf_slot, result);
    cullLandmarks(map_.keyframe(kf_slot).id);
  }
  recordPeakCounts();
  publishSnapshot(kf_slot);
  return refine;
}

void LocalMapper::recordPeakCounts() {
  const MapCounts counts = map_.counts();
  stats_.peak.keyframes = std::max(stats_.peak.keyframes, counts.keyframes);
  stats_.peak.points = std::max(stats_.peak.points, counts.points);
  stats_.peak.lines = std::max(stats_.peak.lines, counts.lines);
  stats_.peak.point_observations = std::max(stats_.peak.point_observations, counts.point_observations);
  stats_.peak.line_observations = std::max(stats_.peak.line_observations, counts.line_observations);
}

InsertResult LocalMapper::addUnrefined(const KeyframeRequest& request) {
  InsertResult result;
  unrefined_slot_ = -1;
  if (request.start_new_map) {
    retireAll();
    map_.clear();
    loop_corrections_ = 0;
    T_loop_corrections_ = Eigen::Isometry3d::Identity();
    ++segment_;
    ++stats_.segments;
  } else if (map_.counts().keyframes == 0) {
    return result;  // nothing to attach to: the tracker must start a map first
  }
  if (map_.counts().keyframes >= kMaxMapKeyframes) retireKeyframe(map_.oldestKeyframeSlot());
  const int kf_slot = map_.addKeyframe();
  Keyframe& kf = map_.keyframe(kf_slot);
  kf.frame_sequence = request.frame_sequence;
  kf.timestamp_s = request.timestamp_s;
  kf.T_world_cam = request.T_world_cam;
  kf.uncertainty.twist_per_s = request.twist_per_s;
  // Tracked against a snapshot from before the last loop correction: move it with the map.
  if (!request.start_new_map && request.local_map_version < correction_version_) {
    kf.T_world_cam = last_correction_ * request.T_world_cam;
  }
  if (request.start_new_map) {
    // The world frame is the first map's first keyframe (exact); a later segment starts at the
    // last known pose, a guess (docs/UNCERTAINTY.md).
    const UncertaintyOptions& u = options_.uncertainty;
    kf.uncertainty.world_covariance =
        segment_ <= 1 ? Eigen::Matrix<double, 6, 6>::Zero()
                      : diagonalPoseCovariance(u.segment_translation_sigma_m, u.segment_rotation_sigma_rad);
    kf.uncertainty.world_covariance_valid = true;
  }
  result.inserted = true;
  result.keyframe_id = kf.id;
  ++stats_.keyframes_inserted;

  if (!request.start_new_map) {
    applyVisibility(request);
    addTrackedObservations(kf_slot, request);
  }
  result.new_points = createPoints(kf_slot, request);
  result.new_lines = options_.tracker.use_lines ? createLines(kf_slot, request) : 0;
  unrefined_slot_ = kf_slot;
  unrefined_new_map_ = request.start_new_map;
  return result;
}

bool LocalMapper::applyCorrection(const MapCorrection& correction) {
  const int kf_slot = map_.findKeyframeSlot(correction.keyframe_id);
  if (kf_slot < 0) return false;
  const Eigen::Isometry3d C = correction.T_world_cam * map_.keyframe(kf_slot).T_world_cam.inverse();
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    if (map_.keyframeAlive(int(i))) map_.keyframe(int(i)).T_world_cam = C * map_.keyframe(int(i)).T_world_cam;
  }
  for (std::size_t i = 0; i < kMaxMapPoints; ++i) {
    if (map_.pointAlive(int(i))) map_.point(int(i)).P_world = C * map_.point(int(i)).P_world;
  }
  for (std::size_t i = 0; i < kMaxMapLines; ++i) {
    if (!map_.lineAlive(int(i))) continue;
    MapLine& l = map_.line(int(i));
    for (int s = 0; s < l.num_samples; ++s) l.samples_world[std::size_t(s)] = C * l.samples_world[std::size_t(s)];
    l.start_world = C * l.start_world;
    l.end_world = C * l.end_world;
  }
  last_correction_ = C;
  ++loop_corrections_;
  T_loop_corrections_ = C * T_loop_corrections_;
  publishSnapshot(map_.newestKeyframeSlot());
  correction_version_ = local_map_->version;
  return true;
}

void LocalMapper::applyVisibility(const KeyframeRequest& request) {
  for (const LandmarkVisibility& v : request.point_visibility) {
    MapPoint& p = map_.point(int(v.ref.slot));
    if (p.id != v.ref.id) continue;
    p.tracking.visible += v.visible;
    p.tracking.found += v.found;
  }
  for (const LandmarkVisibility& v : request.line_visibility) {
    MapLine& l = map_.line(int(v.ref.slot));
    if (l.id != v.ref.id) continue;
    l.tracking.visible += v.visible;
    l.tracking.found += v.found;
  }
}

namespace {

KeyframePointObservation pointObservation(const KeypointObservation& kp, uint32_t point_slot, uint16_t index,
                                          const NoiseModelOptions& noise, const CameraIntrinsics& intrinsics) {
  KeyframePointObservation obs;
  obs.point_slot = point_slot;
  obs.keypoint_index = index;
  obs.octave = kp.octave;
  // u_r may be negative (a near point at the left border): depth decides, not its sign.
  obs.has_depth = kp.depth_m > 0;
  const bool has_depth = obs.has_depth;
  obs.uvr = Eigen::Vector3d(kp.px_undist.x(), kp.px_undist.y(), has_depth ? kp.u_right : 0.0);
  if (has_depth) {
    obs.info = kp.info_uvr.cast<double>();
    if (!(obs.info.trace() > 0)) obs.info = stereoPointInformation(noise, intrinsics, kp.octave, kp.depth_m);
  } else {
    obs.info.setZero();
    obs.info.topLeftCorner<2, 2>() = monoPointInformation(noise, kp.octave);
  }
  return obs;
}

KeyframeLineObservation lineObservation(const LineObservation& line, uint32_t line_slot, uint16_t index,
                                        const NoiseModelOptions& noise) {
  KeyframeLineObservation obs;
  obs.line_slot = line_slot;
  obs.line_index = index;
  obs.octave = line.octave;
  obs.l = line.l;
  obs.info = lineSampleInformation(noise, line.octave);
  return obs;
}

}  // namespace

void LocalMapper::addTrackedObservations(int kf_slot, const KeyframeRequest& request) {
  const FrameFeatures& f = request.features;
  const NoiseModelOptions& noise = options_.extractor.noise;
  for (std::size_t k = 0; k < f.keypoints.size(); ++k) {
    const LandmarkRef& ref = request.keypoint_landmark[k];
    if (ref.id == 0) continue;
    MapPoint& p = map_.point(int(ref.slot));
    if (p.id != ref.id) {
      ++stats_.stale_associations;
      continue;
    }
    (void)map_.addPointObservation(kf_slot, pointObservation(f.keypoints[k], ref.slot, uint16_t(k), noise, intrinsics_));
  }
  for (std::size_t k = 0; k < f.lines.size(); ++k) {
    const LandmarkRef& ref = request.line_landmark[k];
    if (ref.id == 0) continue;
    MapLine& l = map_.line(int(ref.slot));
    if (l.id != ref.id) {
      ++stats_.stale_associations;
      continue;
    }
    (void)map_.addLineObservation(kf_slot, lineObservation(f.lines[k], ref.slot, uint16_t(k), noise));
  }
}

int LocalMapper::createPoints(int kf_slot, const KeyframeRequest& request) {
  const FrameFeatures& f = request.features;
  Keyframe& kf = map_.keyframe(kf_slot);
  // Closest first (ORB-SLAM2's RGB-D rule): near depth is the precise part of an RGB-D map.
  auto& order = s_->new_point_order;
  order.clear();
  for (std::size_t k = 0; k < f.keypoints.size(); ++k) {
    const KeypointObservation& kp = f.keypoints[k];
    if (request.keypoint_landmark[k].id != 0) continue;
    if (kp.depth_m <= 0 || kp.depth_m > options_.mapper.max_new_point_depth_m) continue;
    (void)order.push_back({kp.depth_m, uint16_t(k)});
  }
  std::sort(order.begin(), order.end());  // ties broken by keypoint index: deterministic
  const std::size_t wanted = std::min<std::size_t>(order.size(), std::size_t(options_.mapper.max_new_points));
  freePointSlots(wanted);
  const Eigen::Isometry3d& T = kf.T_world_cam;
  int created = 0;
  for (std::size_t i = 0; i < wanted; ++i) {
    const uint16_t k = order[i].second;
    const KeypointObservation& kp = f.keypoints[k];
    const int slot = map_.addPoint();
    if (slot < 0) break;
    MapPoint& p = map_.point(slot);
    p.P_world = T * kp.P_cam.cast<double>();
    p.descriptor = f.keypoint_descriptors[k];
    p.ref_distance_m = kp.P_cam.norm();
    p.ref_octave = kp.octave;
    p.first_keyframe_id = kf.id;
    if (!map_.addPointObservation(kf_slot, pointObservation(kp, uint32_t(slot), k, options_.extractor.noise,
                                                             intrinsics_))) {
      map_.removePoint(slot);
      break;
    }
    ++created;
  }
  stats_.points_created += uint64_t(created);
  return created;
}

int LocalMapper::createLines(int kf_slot, const KeyframeRequest& request) {
  const FrameFeatures& f = request.features;
  Keyframe& kf = map_.keyframe(kf_slot);
  const Eigen::Isometry3d& T = kf.T_world_cam;
  std::size_t wanted = 0;
  for (std::size_t k = 0; k < f.lines.size(); ++k) {
    if (request.line_landmark[k].id == 0 && f.lines[k].has_3d && f.lines[k].num_samples >= 2) ++wanted;
  }
  wanted = std::min<std::size_t>(wanted, std::size_t(options_.mapper.max_new_lines));
  freeLineSlots(wanted);
  int created = 0;
  // Lines arrive ranked by response (best first), so the first ones are the ones kept.
  for (std::size_t k = 0; k < f.lines.size() && std::size_t(created) < wanted; ++k) {
    const LineObservation& obs = f.lines[k];
    if (request.line_landmark[k].id != 0 || !obs.has_3d || obs.num_samples < 2) continue;
    const int slot = map_.addLine();
    if (slot < 0) break;
    MapLine& l = map_.line(slot);
    l.num_samples = obs.num_samples;
    for (int s = 0; s < obs.num_samples; ++s) {
      l.samples_first_cam[s] = obs.sample_P_cam[s];
      l.samples_world[s] = T * obs.sample_P_cam[s].cast<double>();
    }
    Eigen::Vector3d start_cam, end_cam;
    mapLineEndpointsCam(camera_, obs, &start_cam, &end_cam);
    l.start_world = T * start_cam;
    l.end_world = T * end_cam;
    l.descriptor = f.line_descriptors[k];
    l.ref_octave = obs.octave;
    l.first_keyframe_id = kf.id;
    if (!map_.addLineObservation(kf_slot, lineObservation(obs, uint32_t(slot), uint16_t(k), options_.extractor.noise))) {
      map_.removeLine(slot);
      break;
    }
    ++created;
  }
  stats_.lines_created += uint64_t(created);
  return created;
}

// When the landmark arrays are full, the worst landmarks go first: fewest observers, then lowest
// found/visible ratio, then oldest.
void LocalMapper::freePointSlots(std::size_t needed) {
  if (map_.freePointSlots() >= needed) return;
  auto& order = s_->retire_order;
  order.clear();
  for (std::size_t i = 0; i < kMaxMapPoints; ++i) {
    const MapPoint& p = map_.point(int(i));
    if (p.id == 0) continue;
    const float score = float(p.observers.count()) + p.tracking.foundRatio() + 1e-9f * float(p.id);
    (void)order.push_back({score, uint32_t(i)});
  }
  const std::size_t count = std::min(order.size(), needed - map_.freePointSlots());
  std::partial_sort(order.begin(), order.begin() + count, order.end());
  for (std::size_t i = 0; i < count; ++i) map_.removePoint(int(order[i].second));
  stats_.points_culled += count;
}

void LocalMapper::freeLineSlots(std::size_t needed) {
  if (map_.freeLineSlots() >= needed) return;
  auto& order = s_->retire_order;
  order.clear();
  for (std::size_t i = 0; i < kMaxMapLines; ++i) {
    const MapLine& l = map_.line(int(i));
    if (l.id == 0) continue;
    const float score = float(l.observers.count()) + l.tracking.foundRatio() + 1e-9f * float(l.id);
    (void)order.push_back({score, uint32_t(i)});
  }
  const std::size_t count = std::min(order.size(), needed - map_.freeLineSlots());
  std::partial_sort(order.begin(), order.begin() + count, order.end());
  for (std::size_t i = 0; i < count; ++i) map_.removeLine(int(order[i].second));
  stats_.lines_culled += count;
}

// ORB-SLAM's MapPointCulling: a young landmark must be found in enough of the frames that should
// see it, and be observed by a second keyframe once a few keyframes have passed.
void LocalMapper::cullLandmarks(uint32_t current_keyframe_id) {
  const LocalMapperOptions& o = options_.mapper;
  const uint32_t young_age = uint32_t(o.cull_after_keyframes);
  for (std::size_t i = 0; i < kMaxMapPoints; ++i) {
    const MapPoint& p = map_.point(int(i));
    if (p.id == 0) continue;
    const uint32_t age = current_keyframe_id - p.first_keyframe_id;
    if (age > young_age) continue;
    const bool rarely_found = p.tracking.visible >= 4 && p.tracking.foundRatio() < o.min_found_ratio;
    const bool unconfirmed = age >= young_age - 1 && p.observers.count() < o.min_observers;
    if (rarely_found || unconfirmed) {
      map_.removePoint(int(i));
      ++stats_.points_culled;
    }
  }
  for (std::size_t i = 0; i < kMaxMapLines; ++i) {
    const MapLine& l = map_.line(int(i));
    if (l.id == 0) continue;
    const bool failing = l.sample_evaluations >= 10 &&
                         float(l.sample_outliers) > o.max_line_sample_outlier_ratio * float(l.sample_evaluations);
    const uint32_t age = current_keyframe_id - l.first_keyframe_id;
    const bool young = age <= young_age;
    const bool rarely_found = young && l.tracking.visible >= 4 && l.tracking.foundRatio() < o.min_found_ratio;
    const bool unconfirmed = young && age >= young_age - 1 && l.observers.count() < o.min_observers;
    if (failing || rarely_found || unconfirmed) {
      map_.removeLine(int(i));
      ++stats_.lines_culled;
    }
  }
}

}  // namespace plumb
