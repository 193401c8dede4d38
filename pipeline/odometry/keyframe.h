#pragma once
// Keyframe: a frame kept in the map with its pose and the measurements that tie it to landmarks
// (what local BA needs). Measurements are copied out of the frame's FrameFeatures when the
// keyframe is inserted, so a keyframe does not hold on to a frame slot.
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pipeline/frontend/capacities.h"
#include "pipeline/odometry/keyframe_uncertainty.h"
#include "pipeline/odometry/map_capacities.h"
#include "platform/fixed_vector.h"

namespace plumb {

// An RGB-D point measurement [u, v, u_r] (has_depth false: a 2D-only [u, v] measurement) with its
// information matrix from the front end's noise model.
struct KeyframePointObservation {
  uint32_t point_slot = 0;
  uint16_t keypoint_index = 0;  // index into the keyframe's FrameFeatures at insertion
  int8_t octave = 0;
  bool has_depth = true;
  Eigen::Vector3d uvr = Eigen::Vector3d::Zero();
  Eigen::Matrix3d info = Eigen::Matrix3d::Identity();
};

// A line measurement: the normalised 2D line l of the matched segment; every line-guidance sample
// of the landmark contributes l^T pi(T P_s) with information `info` (1/pixel sigma^2).
struct KeyframeLineObservation {
  uint32_t line_slot = 0;
  uint16_t line_index = 0;
  int8_t octave = 0;
  Eigen::Vector3d l = Eigen::Vector3d::Zero();
  double info = 1.0;
};

struct Keyframe {
  uint32_t id = 0;  // 0 = free slot; ids grow forever
  uint64_t frame_sequence = 0;
  double timestamp_s = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  // Marginal covariance of the pose from the last local BA that optimised it (tangent space of
  // the solver's SE(3) perturbation); zero until then.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_valid = false;
  KeyframeUncertainty uncertainty;  // relative to the previous keyframe, and in the world frame
  FixedVector<KeyframePointObservation, kMaxKeypoints> points;
  FixedVector<KeyframeLineObservation, kMaxLines> lines;
};

}  // namespace plumb
