#pragma once
// Landmarks of the odometry map: map points (one 3D point each) and map lines (the paper's line
// guidance features: N 3D points sampled on one observed segment plus its LBD descriptor).
// Both live in fixed slots of the Map; `id == 0` marks a free slot. Ids grow forever and are never
// reused, so a message that names (slot, id) can detect that the slot was recycled meanwhile.
#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "pipeline/frontend/frame_features.h"
#include "pipeline/odometry/map_capacities.h"

namespace plumb {

// Which keyframe slots observe a landmark, and where in each keyframe's observation list.
struct LandmarkObservers {
  KeyframeMask mask = 0;
  std::array<uint16_t, kMaxMapKeyframes> obs_index{};  // valid where the mask bit is set

  int count() const { return __builtin_popcount(mask); }
  bool has(int kf_slot) const { return (mask >> kf_slot) & 1u; }
};

// Tracking statistics for culling (ORB-SLAM's found/visible ratio): `visible` counts frames whose
// predicted view contained the landmark, `found` the frames where it was matched as an inlier.
struct LandmarkTrackingStats {
  uint32_t visible = 1;
  uint32_t found = 1;
  float foundRatio() const { return visible == 0 ? 0.f : float(found) / float(visible); }
};

struct MapPoint {
  uint32_t id = 0;  // 0 = free slot
  Eigen::Vector3d P_world = Eigen::Vector3d::Zero();
  Descriptor256 descriptor;
  // Scale prediction: the point was seen at `ref_distance_m` on pyramid level `ref_octave`, so at
  // distance d it is expected on level ref_octave + log(ref_distance_m / d) / log(1.2).
  float ref_distance_m = 1.f;
  int8_t ref_octave = 0;
  uint32_t first_keyframe_id = 0;
  LandmarkObservers observers;
  LandmarkTrackingStats tracking;
};

struct MapLine {
  uint32_t id = 0;  // 0 = free slot
  uint8_t num_samples = 0;
  std::array<Eigen::Vector3d, kMaxLineSamples> samples_world{};  // the line guidance points
  // The segment's 3D endpoints (for matching by projection: predicted endpoints and direction).
  Eigen::Vector3d start_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d end_world = Eigen::Vector3d::Zero();
  Descriptor256 descriptor;  // LBD
  int8_t ref_octave = 0;
  uint32_t first_keyframe_id = 0;
  // Each sample as its first keyframe back-projected it (camera frame, m): local BA's anchor
  // observation of the sample's depth (LocalMapperOptions::anchor_line_sample_depth).
  std::array<Eigen::Vector3f, kMaxLineSamples> samples_first_cam{};
  LandmarkObservers observers;
  LandmarkTrackingStats tracking;
  // Sample residuals classified as outliers by local BA, out of all sample residuals: a line
  // whose samples keep failing sits on a depth discontinuity and is culled.
  uint32_t sample_outliers = 0;
  uint32_t sample_evaluations = 0;
};

}  // namespace plumb
