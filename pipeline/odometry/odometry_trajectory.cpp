#include "pipeline/odometry/odometry_trajectory.h"

#include <algorithm>

namespace plumb {

OdometryTrajectory::OdometryTrajectory(int delay_frames)
    : delay_(std::clamp(delay_frames, 0, kMaxDelayFrames - 1)) {}

bool OdometryTrajectory::push(uint64_t sequence, double timestamp_s, bool valid, const Eigen::Isometry3d& T_world_cam,
                              uint32_t reference_id, const Eigen::Isometry3d& T_ref_cam) {
  if (full()) return false;
  Pending& p = fifo_[(head_ + size_) % kMaxDelayFrames];
  ++size_;
  p.frame.sequence = sequence;
  p.frame.timestamp_s = timestamp_s;
  p.frame.valid = valid;
  p.frame.dropped = false;
  p.frame.T_world_cam = T_world_cam;
  p.reference_id = valid ? reference_id : 0;
  p.T_ref_cam = T_ref_cam;
  p.world = world_;
  p.frame.loop_epoch = world_.loop_epoch;
  return true;
}

FinishedFrame OdometryTrajectory::resolve(const LocalMap& map, const Pending& p) const {
  FinishedFrame out = p.frame;
  out.reference_id = p.reference_id;
  out.T_ref_cam = p.T_ref_cam;
  // Delay 0 means poses as tracked (docs): the reference keyframe's own local BA must not move
  // them; with a delay they follow their reference keyframe's refinements.
  if (p.reference_id == 0 || delay_ == 0) return out;
  for (const LocalMapKeyframe& kf : map.keyframes) {
    if (kf.id == p.reference_id) {
      out.T_world_cam = kf.T_world_cam * p.T_ref_cam;
      // Corrected since the frame was queued: back into the world it was tracked in.
      if (map.segment == p.world.segment && map.loop_corrections != p.world.corrections) {
        out.T_world_cam = p.world.T_corrections * map.T_loop_corrections.inverse() * out.T_world_cam;
      }
      break;
    }
  }
  return out;
}

}  // namespace plumb
