#pragma once
// Relocalizer: recovers the pose of a frame when tracking is lost, against keyframes remembered in
// a bounded ring (kMaxRelocKeyframes, independent of the map window). No vocabulary file: each
// stored keyframe keeps up to kMaxRelocFeatures ORB descriptors with their 3D points (camera
// frame, from depth).
//
//   1. rank stored keyframes by brute-force Hamming matches of a subset of the frame's features;
//   2. for the best few: full matching (threshold + ratio test), then RANSAC over 3-point
//      rigid fits (3D-3D with both depths, Horn/Umeyama), seeded with a fixed seed;
//   3. refine with the pose-only optimiser against the inliers' [u, v, u_r] observations.
// Deterministic: iteration orders are fixed and the sampler restarts from the seed on each call.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "sensor/camera.h"
#include "pipeline/frontend/frame_features.h"
#include "pipeline/odometry/map_capacities.h"
#include "pipeline/odometry/odometry_options.h"
#include "platform/memory_residency.h"
#include "solver/camera_intrinsics.h"
#include "solver/zero_page_allocator.h"

namespace plumb {

struct RelocResult {
  bool success = false;
  uint32_t keyframe_id = 0;  // the stored keyframe it relocalized against
  int candidates_tried = 0;
  int matches = 0;
  int ransac_inliers = 0;
  int refined_inliers = 0;
};

class Relocalizer {
 public:
  Relocalizer(const PinholeCamera& camera, const OdometryOptions& options);
  ~Relocalizer();

  // Remembers a keyframe (the oldest stored one is overwritten when the ring is full).
  void addKeyframe(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam, const FrameFeatures& frame);
  // Remembers a keyframe of a loaded map from its stored features (n descriptors with their 3D
  // points in the keyframe's camera frame; the first kMaxRelocFeatures are kept).
  void addStoredKeyframe(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam, std::size_t n,
                         const Descriptor256* descriptors, const Eigen::Vector3f* P_cam);
  // Replaces the pose of a stored keyframe (after local BA refined it); unknown ids are ignored.
  void updatePose(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam);
  std::size_t size() const { return count_; }
  void clear() { count_ = 0; next_ = 0; }

  RelocResult relocalize(const FrameFeatures& frame, Eigen::Isometry3d* T_world_cam);

 private:
  struct StoredKeyframe {
    uint32_t id = 0;
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
    FixedVector<Descriptor256, kMaxRelocFeatures> descriptors;
    FixedVector<Eigen::Vector3f, kMaxRelocFeatures> P_cam;
  };
  struct Correspondence {
    uint16_t keypoint = 0;          // current frame
    Eigen::Vector3d P_current;      // current camera frame
    Eigen::Vector3d P_stored;       // stored keyframe camera frame
  };

  // The next slot of the ring (the oldest keyframe gives way), emptied and given id and pose.
  StoredKeyframe& claimSlot(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam);
  int countMatches(const StoredKeyframe& kf, const FrameFeatures& frame) const;
  int matchAll(const StoredKeyframe& kf, const FrameFeatures& frame);
  bool ransac(Eigen::Isometry3d* T_stored_current, int* inliers);
  int refine(const FrameFeatures& frame, const StoredKeyframe& kf, Eigen::Isometry3d* T_cam_world);

  PinholeCamera camera_;
  CameraIntrinsics intrinsics_;
  OdometryOptions options_;
  // The ring of stored keyframes (~1.2 MB), from kernel zero pages (all-zero bytes: empty
  // feature lists; a slot is claimed before it is read): it is not written at construction, so
  // the first pose does not wait for it. addKeyframe() makes a slice resident per keyframe from
  // the second on, so the resident set stops growing after a few keyframes (as with the loop
  // closer, platform/memory_residency.h).
  std::vector<StoredKeyframe, ZeroPageAllocator<StoredKeyframe>> stored_;
  ResidencyQueue residency_;
  std::size_t keyframes_added_ = 0;
  std::size_t count_ = 0;
  std::size_t next_ = 0;  // ring position of the next insertion
  // Matching / RANSAC / pose scratch (~250 KB), from zero pages: written before it is read (the
  // all-zero bytes are empty lists and false flags), so only what a relocalization (or the
  // keyframe ranking of addKeyframe) reaches becomes resident.
  struct Scratch;
  struct ScratchDeleter {
    void operator()(Scratch* s) const;
  };
  std::unique_ptr<Scratch, ScratchDeleter> s_;
};

}  // namespace plumb
