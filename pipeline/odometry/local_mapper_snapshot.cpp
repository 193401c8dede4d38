// LocalMapper: building the tracker's LocalMap snapshot after a keyframe.
#include <algorithm>

#include "pipeline/odometry/local_mapper.h"

namespace plumb {

void LocalMapper::buildSnapshot(int kf_slot, LocalMap* out_map) {
  LocalMap& out = *out_map;
  out.clear();
  out.version = ++snapshot_version_;
  out.segment = segment_;
  out.loop_corrections = loop_corrections_;
  out.T_loop_corrections = T_loop_corrections_;
  const Keyframe& reference = map_.keyframe(kf_slot);
  out.reference_keyframe_id = reference.id;
  out.reference_keyframe_sequence = reference.frame_sequence;
  out.T_world_reference = reference.T_world_cam;
  out.reference_world_covariance = reference.uncertainty.world_covariance;
  out.reference_world_covariance_valid = reference.uncertainty.world_covariance_valid;

  // Every keyframe of the map, by id (the system resolves reference-relative frame poses).
  FixedVector<std::pair<uint32_t, int>, kMaxMapKeyframes> by_id;
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    if (map_.keyframeAlive(int(i))) (void)by_id.push_back({map_.keyframe(int(i)).id, int(i)});
  }
  std::sort(by_id.begin(), by_id.end());
  for (const auto& k : by_id) {
    (void)out.keyframes.push_back(LocalMapKeyframe{k.first, map_.keyframe(k.second).T_world_cam});
  }
  out.keyframes_in_map = int(by_id.size());

  // Landmarks of the reference keyframe observed by at least two keyframes (ORB-SLAM's
  // "tracked" map points of the reference), the baseline of the keyframe policy.
  const int min_observers = out.keyframes_in_map > 2 ? 2 : 1;
  int tracked = 0;
  for (const auto& obs : reference.points) tracked += map_.point(int(obs.point_slot)).observers.count() >= min_observers;
  for (const auto& obs : reference.lines) tracked += map_.line(int(obs.line_slot)).observers.count() >= min_observers;
  out.reference_tracked_landmarks = tracked;

  // Local keyframes: the reference and its best covisible neighbours; their landmarks, the
  // reference's first, up to the snapshot's capacity.
  FixedVector<int, kMaxMapKeyframes> local;
  rankCovisible(kf_slot, options_.mapper.covisible_keyframes_in_local_map, &local);
  (void)local.push_back(kf_slot);
  std::rotate(local.begin(), local.end() - 1, local.end());
  ++stamp_;
  for (int slot : local) {
    const Keyframe& kf = map_.keyframe(slot);
    for (const auto& obs : kf.points) {
      if (s_->point_stamp[obs.point_slot] == stamp_ || out.points.full()) continue;
      s_->point_stamp[obs.point_slot] = stamp_;
      const MapPoint& p = map_.point(int(obs.point_slot));
      LocalMapPoint* lp = out.points.emplace_back();
      lp->ref = LandmarkRef{obs.point_slot, p.id};
      lp->P_world = p.P_world;
      lp->descriptor = p.descriptor;
      lp->ref_distance_m = p.ref_distance_m;
      lp->ref_octave = p.ref_octave;
      lp->keyframe_observations = uint8_t(std::clamp(p.observers.count(), 1, 255));
    }
    for (const auto& obs : kf.lines) {
      if (s_->line_stamp[obs.line_slot] == stamp_ || out.lines.full()) continue;
      s_->line_stamp[obs.line_slot] = stamp_;
      const MapLine& l = map_.line(int(obs.line_slot));
      LocalMapLine* ll = out.lines.emplace_back();
      ll->ref = LandmarkRef{obs.line_slot, l.id};
      ll->num_samples = l.num_samples;
      ll->samples_world = l.samples_world;
      ll->start_world = l.start_world;
      ll->end_world = l.end_world;
      ll->descriptor = l.descriptor;
      ll->keyframe_observations = uint8_t(std::clamp(l.observers.count(), 1, 255));
    }
  }
}

}  // namespace plumb
