#pragma once
// OdometryTrajectory: turns per-frame tracking results into the output trajectory.
//
// Frames are stored relative to their reference keyframe (T_ref_cam, ORB-SLAM style) and held in
// a bounded FIFO for `delay_frames` frames; when a frame leaves the FIFO its pose is
// T_world_ref * T_ref_cam with the reference keyframe's CURRENT (local-BA refined) pose, so the
// corrections BA makes after the frame was tracked reach the trajectory. A reference keyframe no
// longer in the map leaves the pose as tracked. delay_frames = 0 outputs every frame exactly as
// tracked, a keyframe too (whose own local BA ran before it leaves): what a controller was sent
// (MAVLink, docs/MAVLINK.md) is then what the trajectory file says.
#include <array>
#include <cstdint>

#include <Eigen/Geometry>

#include "pipeline/odometry/local_map.h"
#include "sensor/stamped_pose.h"

namespace plumb {

struct FinishedFrame {
  uint64_t sequence = 0;
  double timestamp_s = 0;
  bool valid = false;  // false: no pose (lost / not initialised)
  bool dropped = false;  // never processed (real-time replay found no free slot); valid is false
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  // The keyframe the pose was expressed against (0: none) and the pose relative to it: loop
  // closing's optimised trajectory re-expresses the frame through that keyframe's final pose.
  uint32_t reference_id = 0;
  Eigen::Isometry3d T_ref_cam = Eigen::Isometry3d::Identity();
  // Loop corrections the mapping side had applied when the frame was queued: the world frame
  // T_world_cam is in (each correction moves the map; a frame keeps the world it was tracked in).
  uint64_t loop_epoch = 0;
};

// The frame as a trajectory sample: what trajectory files, the tools and the API keep of it.
inline StampedPose toStampedPose(const FinishedFrame& frame) {
  StampedPose pose;
  pose.timestamp = frame.timestamp_s;
  pose.T_world_cam = frame.T_world_cam;
  pose.valid = frame.valid;
  pose.dropped = frame.dropped;
  return pose;
}

class OdometryTrajectory {
 public:
  static constexpr int kMaxDelayFrames = 256;
  explicit OdometryTrajectory(int delay_frames);

  // Adds a frame. reference_id 0 = no reference (pose used as given). false, and nothing is
  // overwritten, when the queue is full: the caller must pop ready frames after every push (the
  // runner does); full() tells beforehand.
  bool push(uint64_t sequence, double timestamp_s, bool valid, const Eigen::Isometry3d& T_world_cam,
            uint32_t reference_id, const Eigen::Isometry3d& T_ref_cam);
  // A frame the runtime dropped before processing: it keeps its place in the output order.
  bool pushDropped(uint64_t sequence, double timestamp_s) {
    if (!push(sequence, timestamp_s, false, Eigen::Isometry3d::Identity(), 0, Eigen::Isometry3d::Identity()))
      return false;
    fifo_[(head_ + size_ - 1) % kMaxDelayFrames].frame.dropped = true;
    return true;
  }
  bool full() const { return size_ >= kMaxDelayFrames; }
  // The world the frames pushed from now on are in: `loop_epoch` loop corrections applied so far
  // (all segments), and of the map segment `segment`, `corrections` of them composing to
  // `T_corrections` (LocalMap::loop_corrections / T_loop_corrections). A frame is resolved in ITS
  // world: a correction applied while it waits in the queue does not move it (it was tracked, and
  // sent to the robot, before the correction; docs/LOOP.md "What the robot receives").
  void setWorld(uint64_t loop_epoch, uint32_t segment, uint64_t corrections, const Eigen::Isometry3d& T_corrections) {
    world_ = World{loop_epoch, segment, corrections, T_corrections};
  }
  // Frames leaving the FIFO, resolved against the keyframe poses of `map`; calls fn(FinishedFrame)
  // for each. flushAll empties the FIFO (end of run).
  template <typename Fn>
  void popReady(const LocalMap& map, Fn fn) { pop(map, false, fn); }
  template <typename Fn>
  void flushAll(const LocalMap& map, Fn fn) { pop(map, true, fn); }

 private:
  struct World {
    uint64_t loop_epoch = 0;
    uint32_t segment = 0;
    uint64_t corrections = 0;
    Eigen::Isometry3d T_corrections = Eigen::Isometry3d::Identity();
  };
  struct Pending {
    FinishedFrame frame;
    uint32_t reference_id = 0;
    Eigen::Isometry3d T_ref_cam = Eigen::Isometry3d::Identity();
    World world;
  };
  template <typename Fn>
  void pop(const LocalMap& map, bool all, Fn fn) {
    while (size_ > 0 && (all || size_ > delay_)) {
      Pending& p = fifo_[head_];
      head_ = (head_ + 1) % kMaxDelayFrames;
      --size_;
      fn(resolve(map, p));
    }
  }
  FinishedFrame resolve(const LocalMap& map, const Pending& p) const;

  int delay_;
  World world_;
  std::array<Pending, kMaxDelayFrames> fifo_{};
  int head_ = 0;
  int size_ = 0;
};

}  // namespace plumb
