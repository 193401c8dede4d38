// Tracker: association of the current frame's features with 3D points (last frame, local map).
#include <cmath>

#include "pipeline/odometry/tracker.h"

namespace plumb {

void Tracker::clearAssociations(const FrameFeatures& frame) {
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) b_->points[k] = PointAssociation{};
  for (std::size_t k = 0; k < frame.lines.size(); ++k) b_->lines[k] = LineAssociation{};
}

int Tracker::matchLastFrame(const FrameFeatures& frame, const Eigen::Isometry3d& T_cam_world_pred,
                            ProjectionMatcher& matcher) {
  const Eigen::Isometry3d T_cur_last = T_cam_world_pred * T_world_last_;
  int matched = 0;
  matcher.matchPointsFrameToFrame(camera_, b_->last_frame, T_cur_last, frame, b_->point_matches);
  for (const PointMatch& m : b_->point_matches) {
    const PointAssociation& last = b_->last_points[m.candidate];
    if (!last.valid) continue;
    b_->points[m.keypoint] = last;
    b_->points[m.keypoint].local_index = -1;
    ++matched;
  }
  if (!options_.tracker.use_lines) return matched;
  matcher.matchLinesFrameToFrame(camera_, b_->last_frame, T_cur_last, frame, b_->line_matches);
  for (const LineMatch& m : b_->line_matches) {
    const LineAssociation& last = b_->last_lines[m.candidate];
    if (!last.valid) continue;
    b_->lines[m.line] = last;
    b_->lines[m.line].local_index = -1;
    ++matched;
  }
  return matched;
}

namespace {

// ORB-SLAM's scale prediction: a point seen at distance d0 on level o0 appears at distance d on
// level o0 + log(d0 / d) / log(scale).
int predictOctave(float ref_distance_m, int ref_octave, double distance_m, double log_scale, int levels) {
  const int octave = ref_octave + int(std::lround(std::log(ref_distance_m / distance_m) / log_scale));
  return octave < 0 ? 0 : (octave >= levels ? levels - 1 : octave);
}

}  // namespace

int Tracker::matchLocalMap(const FrameFeatures& frame, const Eigen::Isometry3d& T_cam_world) {
  const LocalMap& map = *local_map_;
  const double max_distance = options_.tracker.max_landmark_distance_m;
  const double log_scale = std::log(double(options_.extractor.scale_factor));
  const int levels = options_.extractor.num_levels;
  int added = 0;

  // Landmarks already matched through the last frame: found by slot stamp, not searched again.
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    const PointAssociation& a = b_->points[k];
    if (!a.valid || a.landmark.id == 0) continue;
    b_->point_slot_stamp[a.landmark.slot] = frame_stamp_;
    b_->point_slot_keypoint[a.landmark.slot] = uint16_t(k);
  }
  b_->point_candidates.clear();
  b_->point_candidate_local.clear();
  for (std::size_t i = 0; i < map.points.size(); ++i) {
    const LocalMapPoint& lp = map.points[i];
    if (b_->point_slot_stamp[lp.ref.slot] == frame_stamp_) {
      PointAssociation& a = b_->points[b_->point_slot_keypoint[lp.ref.slot]];
      if (a.landmark.id == lp.ref.id) {
        a.local_index = int(i);
        ++b_->point_visible[i];
        continue;
      }
    }
    const Eigen::Vector3d P_cam = T_cam_world * lp.P_world;
    if (P_cam.z() < 0.1 || P_cam.z() > max_distance) continue;
    const Eigen::Vector2d px = camera_.project(P_cam);
    if (!camera_.inImage(px.x(), px.y())) continue;
    ++b_->point_visible[i];
    PointCandidate* c = b_->point_candidates.emplace_back();
    c->px_undist = px.cast<float>();
    c->descriptor = lp.descriptor;
    c->octave = int8_t(predictOctave(lp.ref_distance_m, lp.ref_octave, P_cam.norm(), log_scale, levels));
    c->angle_deg = -1;
    (void)b_->point_candidate_local.push_back(uint16_t(i));
  }
  local_matcher_.matchPoints(b_->point_candidates.data(), int(b_->point_candidates.size()), frame,
                             b_->point_matches);
  for (const PointMatch& m : b_->point_matches) {
    PointAssociation& a = b_->points[m.keypoint];
    if (a.valid && a.landmark.id != 0) continue;  // keeps the landmark it already has
    const int i = b_->point_candidate_local[m.candidate];
    a.valid = true;
    a.P_world = map.points[i].P_world;
    a.landmark = map.points[i].ref;
    a.local_index = i;
    ++added;
  }

  if (!options_.tracker.use_lines) return added;
  for (std::size_t k = 0; k < frame.lines.size(); ++k) {
    const LineAssociation& a = b_->lines[k];
    if (!a.valid || a.landmark.id == 0) continue;
    b_->line_slot_stamp[a.landmark.slot] = frame_stamp_;
    b_->line_slot_line[a.landmark.slot] = uint16_t(k);
  }
  b_->line_candidates.clear();
  b_->line_candidate_local.clear();
  for (std::size_t i = 0; i < map.lines.size(); ++i) {
    const LocalMapLine& ll = map.lines[i];
    if (b_->line_slot_stamp[ll.ref.slot] == frame_stamp_) {
      LineAssociation& a = b_->lines[b_->line_slot_line[ll.ref.slot]];
      if (a.landmark.id == ll.ref.id) {
        a.local_index = int(i);
        ++b_->line_visible[i];
        continue;
      }
    }
    const Eigen::Vector3d start_cam = T_cam_world * ll.start_world;
    const Eigen::Vector3d end_cam = T_cam_world * ll.end_world;
    if (start_cam.z() < 0.1 || end_cam.z() < 0.1) continue;
    if (start_cam.z() > max_distance && end_cam.z() > max_distance) continue;
    const Eigen::Vector2d start_px = camera_.project(start_cam);
    const Eigen::Vector2d end_px = camera_.project(end_cam);
    const Eigen::Vector2d mid_px = 0.5 * (start_px + end_px);
    if (!camera_.inImage(mid_px.x(), mid_px.y())) continue;
    ++b_->line_visible[i];
    LineCandidate* c = b_->line_candidates.emplace_back();
    c->start_px = start_px.cast<float>();
    c->end_px = end_px.cast<float>();
    c->descriptor = ll.descriptor;
    (void)b_->line_candidate_local.push_back(uint16_t(i));
  }
  local_matcher_.matchLines(b_->line_candidates.data(), int(b_->line_candidates.size()), frame,
                            b_->line_matches);
  for (const LineMatch& m : b_->line_matches) {
    LineAssociation& a = b_->lines[m.line];
    if (a.valid && a.landmark.id != 0) continue;
    const int i = b_->line_candidate_local[m.candidate];
    const LocalMapLine& ll = map.lines[i];
    a.valid = true;
    a.num_samples = ll.num_samples;
    a.samples_world = ll.samples_world;
    a.landmark = ll.ref;
    a.local_index = i;
    ++added;
  }
  return added;
}

}  // namespace plumb
