// Tracker: the last frame follows local BA's corrections when a new snapshot arrives.
//
// The last frame was tracked against the previous snapshot. Local BA has since moved keyframes and
// landmarks (on fr1/rpy the newest keyframe moves by 2.7 mm / 0.16 deg RMS, up to 9 mm). Without
// this update the next frame is matched and optimised against a mix: landmark positions from
// whenever they were first associated (they used to travel frame to frame with the association
// and never saw a BA refinement), back-projected depth points placed with the last frame's old
// pose, and local-map landmarks at their new positions. This is ORB-SLAM2's UpdateLastFrame; on
// its own its effect on the ATE is within the run-to-run spread (docs/ODOMETRY.md).
#include "pipeline/odometry/tracker.h"

namespace plumb {

// Landmark associations only: depth points and the pose follow the reference keyframe below
// (followMapCorrections), which the correction moved by the same motion. Landmarks in the snapshot
// then take the snapshot's positions there; the others would otherwise stay in the world before
// the correction (a loop moves the map by centimetres, BA by millimetres).
void Tracker::followLoopCorrection(const Eigen::Isometry3d& correction) {
  const FrameFeatures& frame = b_->last_frame;
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    PointAssociation& a = b_->last_points[k];
    if (a.valid && a.landmark.id != 0) a.P_world = correction * a.P_world;
  }
  for (std::size_t k = 0; k < frame.lines.size(); ++k) {
    LineAssociation& a = b_->last_lines[k];
    if (!a.valid || a.landmark.id == 0) continue;
    for (int s = 0; s < a.num_samples; ++s) a.samples_world[s] = correction * a.samples_world[s];
  }
}

void Tracker::followMapCorrections() {
  const LocalMap& map = *local_map_;

  // 1. How far the last frame moved: with its reference keyframe, or exactly onto the refined
  //    keyframe when the last frame is the keyframe this snapshot was built for.
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  bool moved = false;
  if (last_sequence_ != kUnknownSequence && map.reference_keyframe_sequence == last_sequence_) {
    correction = map.T_world_reference * T_world_last_.inverse();
    moved = true;
    last_reference_id_ = map.reference_keyframe_id;
    T_world_last_reference_ = map.T_world_reference;
  } else {
    for (const LocalMapKeyframe& kf : map.keyframes) {
      if (kf.id != last_reference_id_) continue;
      correction = kf.T_world_cam * T_world_last_reference_.inverse();
      moved = true;
      T_world_last_reference_ = kf.T_world_cam;
      break;
    }
  }
  const FrameFeatures& frame = b_->last_frame;
  if (moved) {
    T_world_last_ = correction * T_world_last_;
    const Eigen::Matrix3d R = correction.linear();
    const Eigen::Vector3d t = correction.translation();
    // Depth points of the last frame are rigidly attached to it.
    for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
      PointAssociation& a = b_->last_points[k];
      if (a.valid && a.landmark.id == 0) a.P_world = R * a.P_world + t;
    }
    for (std::size_t k = 0; k < frame.lines.size(); ++k) {
      LineAssociation& a = b_->last_lines[k];
      if (!a.valid || a.landmark.id != 0) continue;
      for (int s = 0; s < a.num_samples; ++s) a.samples_world[s] = R * a.samples_world[s] + t;
    }
  }

  // 2. Landmarks take their refined positions (found through their slot; the id check rejects a
  //    slot the mapper has reused). Landmarks outside the snapshot keep the position they had.
  ++frame_stamp_;
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    const PointAssociation& a = b_->last_points[k];
    if (!a.valid || a.landmark.id == 0) continue;
    b_->point_slot_stamp[a.landmark.slot] = frame_stamp_;
    b_->point_slot_keypoint[a.landmark.slot] = uint16_t(k);
  }
  for (std::size_t i = 0; i < map.points.size(); ++i) {
    const LocalMapPoint& lp = map.points[i];
    if (b_->point_slot_stamp[lp.ref.slot] != frame_stamp_) continue;
    PointAssociation& a = b_->last_points[b_->point_slot_keypoint[lp.ref.slot]];
    if (a.landmark.id == lp.ref.id) a.P_world = lp.P_world;
  }
  for (std::size_t k = 0; k < frame.lines.size(); ++k) {
    const LineAssociation& a = b_->last_lines[k];
    if (!a.valid || a.landmark.id == 0) continue;
    b_->line_slot_stamp[a.landmark.slot] = frame_stamp_;
    b_->line_slot_line[a.landmark.slot] = uint16_t(k);
  }
  for (std::size_t i = 0; i < map.lines.size(); ++i) {
    const LocalMapLine& ll = map.lines[i];
    if (b_->line_slot_stamp[ll.ref.slot] != frame_stamp_) continue;
    LineAssociation& a = b_->last_lines[b_->line_slot_line[ll.ref.slot]];
    if (a.landmark.id != ll.ref.id) continue;
    a.num_samples = ll.num_samples;
    a.samples_world = ll.samples_world;
  }
}

}  // namespace plumb
