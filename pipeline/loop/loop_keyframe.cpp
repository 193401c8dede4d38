#include "pipeline/loop/loop_keyframe.h"

#include <algorithm>

#include "pipeline/odometry/local_mapper.h"

namespace plumb::loop {

void fillLoopFeatures(const FrameFeatures& f, LoopKeyframe* out) {
  out->clearFeatures();
  // (-response, index) pairs on the stack (~10 KB): partial sort picks the strongest.
  std::array<std::pair<float, uint16_t>, kMaxKeypoints> order;
  std::size_t n = 0;
  for (std::size_t k = 0; k < f.keypoints.size(); ++k) {
    if (f.keypoints[k].depth_m > 0) order[n++] = {-f.keypoints[k].response, uint16_t(k)};
  }
  const std::size_t keep = std::min(n, kMaxLoopPoints);
  std::partial_sort(order.begin(), order.begin() + keep, order.begin() + n);
  // Keypoint order inside the record: ascending index (stable, deterministic matching order).
  std::sort(order.begin(), order.begin() + keep,
            [](const std::pair<float, uint16_t>& a, const std::pair<float, uint16_t>& b) {
              return a.second < b.second;
            });
  for (std::size_t i = 0; i < keep; ++i) {
    const KeypointObservation& kp = f.keypoints[order[i].second];
    LoopPoint* p = out->points.emplace_back();
    p->P_cam = kp.P_cam;
    p->px = kp.px_undist;
    p->u_right = kp.u_right;
    p->octave = kp.octave;
    (void)out->point_descriptors.push_back(f.keypoint_descriptors[order[i].second]);
  }
  for (std::size_t k = 0; k < f.lines.size() && !out->lines.full(); ++k) {
    const LineObservation& obs = f.lines[k];
    if (!obs.has_3d || obs.num_samples < 2) continue;
    LoopLine* l = out->lines.emplace_back();
    l->l = obs.l.cast<float>();
    l->octave = obs.octave;
    l->num_samples = obs.num_samples;
    for (int s = 0; s < obs.num_samples; ++s)
      l->samples_cam[std::size_t(s)] = obs.sample_P_cam[std::size_t(s)];
    (void)out->line_descriptors.push_back(f.line_descriptors[k]);
  }
}

void makeLoopCandidate(const LoopKeyframe& r, LoopCandidate* out) {
  out->id = r.id;
  out->num_points = uint16_t(r.points.size());
  for (std::size_t k = 0; k < r.points.size(); ++k) {
    out->point_descriptors[k] = r.point_descriptors[k];
    out->P_cam[k] = r.points[k].P_cam;
    out->point_octave[k] = r.points[k].octave;
  }
  out->num_lines = uint16_t(r.lines.size());
  uint16_t next = 0;
  for (std::size_t k = 0; k < r.lines.size(); ++k) {
    const LoopLine& line = r.lines[k];
    out->line_descriptors[k] = r.line_descriptors[k];
    out->num_samples[k] = line.num_samples;
    out->line_octave[k] = line.octave;
    out->first_sample[k] = next;
    for (std::size_t s = 0; s < line.num_samples; ++s) out->samples_cam[next++] = line.samples_cam[s];
  }
}

bool makeLoopKeyframe(const KeyframeRequest& request, uint32_t keyframe_id, bool new_segment,
                      const LocalMapper& mapper, LoopKeyframe* out) {
  const Map& map = mapper.map();
  const int slot = map.findKeyframeSlot(keyframe_id);
  if (slot < 0) return false;
  const Keyframe& kf = map.keyframe(slot);
  out->id = keyframe_id;
  out->frame_sequence = kf.frame_sequence;
  out->timestamp_s = kf.timestamp_s;
  out->new_segment = new_segment;
  out->T_world_cam = kf.T_world_cam;
  out->covariance = kf.covariance;
  out->covariance_valid = kf.covariance_valid;
  // The previous keyframe of this map: the largest id below this one.
  out->previous_id = 0;
  out->T_previous_this = Eigen::Isometry3d::Identity();
  int previous_slot = -1;
  out->window.clear();
  for (int s = 0; s < int(kMaxMapKeyframes); ++s) {
    if (!map.keyframeAlive(s)) continue;
    const uint32_t id = map.keyframe(s).id;
    (void)out->window.push_back(LoopWindowPose{id, map.keyframe(s).T_world_cam});
    if (id < keyframe_id && (previous_slot < 0 || id > map.keyframe(previous_slot).id)) previous_slot = s;
  }
  if (!new_segment && previous_slot >= 0) {
    out->previous_id = map.keyframe(previous_slot).id;
    out->T_previous_this = map.keyframe(previous_slot).T_world_cam.inverse() * kf.T_world_cam;
    // The covariance of exactly this relative pose (local BA's joint marginal, calibrated:
    // docs/UNCERTAINTY.md) when that BA held both keyframes; the marginal otherwise.
    if (kf.uncertainty.previous_id == out->previous_id) {
      out->covariance = kf.uncertainty.relative_covariance;
      out->covariance_valid = true;
    }
  }
  fillLoopFeatures(request.features, out);
  return true;
}

}  // namespace plumb::loop
