#pragma once
// LocalMap: the tracker's read-only view of the map — a plain value the LocalMapper fills after
// each keyframe and the tracker copies in (ORB-SLAM's "local map": the landmarks seen by the
// reference keyframe and its covisible neighbours). No pointers into the Map: landmarks are named
// by (slot, id) so a KeyframeRequest built against an old snapshot is checked when it arrives.
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pipeline/frontend/frame_features.h"
#include "pipeline/odometry/map_capacities.h"
#include "platform/fixed_vector.h"

namespace plumb {

struct LandmarkRef {
  uint32_t slot = 0;
  uint32_t id = 0;  // 0 = none
};

struct LocalMapPoint {
  LandmarkRef ref;
  Eigen::Vector3d P_world = Eigen::Vector3d::Zero();
  Descriptor256 descriptor;
  float ref_distance_m = 1.f;
  int8_t ref_octave = 0;
  uint8_t keyframe_observations = 1;  // keyframes observing it (its position averages them)
};

struct LocalMapLine {
  LandmarkRef ref;
  uint8_t num_samples = 0;
  std::array<Eigen::Vector3d, kMaxLineSamples> samples_world{};
  Eigen::Vector3d start_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d end_world = Eigen::Vector3d::Zero();
  Descriptor256 descriptor;
  uint8_t keyframe_observations = 1;  // keyframes observing it
};

struct LocalMapKeyframe {
  uint32_t id = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
};

struct LocalMap {
  uint64_t version = 0;  // 0 = empty (no map yet)
  uint32_t segment = 0;  // map segment (a new one starts when relocalization keeps failing)
  // The newest keyframe: frames are expressed relative to it and the keyframe policy compares
  // against how many landmarks it tracks.
  uint32_t reference_keyframe_id = 0;
  uint64_t reference_keyframe_sequence = 0;
  Eigen::Isometry3d T_world_reference = Eigen::Isometry3d::Identity();
  // The reference keyframe's world covariance (KeyframeUncertainty), what the tracked pose's
  // published covariance builds on; invalid: the tracked pose gets none.
  Eigen::Matrix<double, 6, 6> reference_world_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool reference_world_covariance_valid = false;
  int reference_tracked_landmarks = 0;  // landmarks of the reference KF observed by >= 2 keyframes
  int keyframes_in_map = 0;
  // Loop corrections the mapper has applied to this map segment so far, and their composition
  // (maps a point of the world before the first of them to the world now). A tracker holding
  // 3D points from an older snapshot moves ALL of them by the difference (Tracker::setLocalMap):
  // a correction moves every landmark, not only those this snapshot lists.
  uint64_t loop_corrections = 0;
  Eigen::Isometry3d T_loop_corrections = Eigen::Isometry3d::Identity();
  FixedVector<LocalMapKeyframe, kMaxMapKeyframes> keyframes;  // every keyframe in the map, by id
  FixedVector<LocalMapPoint, kMaxLocalMapPoints> points;
  FixedVector<LocalMapLine, kMaxLocalMapLines> lines;

  void clear() {
    version = 0;
    reference_keyframe_id = 0;
    reference_world_covariance_valid = false;
    reference_tracked_landmarks = 0;
    keyframes_in_map = 0;
    loop_corrections = 0;
    T_loop_corrections = Eigen::Isometry3d::Identity();
    keyframes.clear();
    points.clear();
    lines.clear();
  }
};

}  // namespace plumb
