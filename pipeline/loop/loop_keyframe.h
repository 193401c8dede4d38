#pragma once
// LoopKeyframe: the compact, fixed-size record of one keyframe that loop closing keeps (docs/LOOP.md).
// Made on the mapping side when a keyframe is inserted (makeLoopKeyframe, from the KeyframeRequest's
// features and the mapper's poses), carried to the loop stage by value through an SPSC ring, and
// stored by the LoopCloser. Nothing in it points anywhere: a plain value of fixed size.
//
//   points: the strongest kMaxLoopPoints keypoints WITH depth: ORB descriptor, 3D point in the camera
//           frame, undistorted pixel, u_r and octave (what descriptor matching, 3D-3D RANSAC and the
//           [u, v, u_r] refinement need);
//   lines:  the first kMaxLoopLines lines with a 3D fit: LBD descriptor, normalised 2D line, octave
//           and the line-guidance samples in the camera frame (the refinement's line errors);
//   odometry: the pose of this keyframe relative to the previous keyframe of the map, taken from the
//           mapper's poses right after this keyframe's local BA, and the covariance of that relative
//           pose from the BA's joint marginal, calibrated (the pose graph's odometry edge and its
//           weight; docs/UNCERTAINTY.md).
// Size: sizeof(LoopKeyframe), ~52 KB (computed in tests/pipeline/loop/loop_verifier_test.cpp). The closer
// keeps only a LoopCandidate of each record (below): what verification reads of a CANDIDATE.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "pipeline/frontend/frame_features.h"
#include "pipeline/odometry/keyframe_request.h"
#include "pipeline/odometry/map_capacities.h"
#include "platform/fixed_vector.h"
#include "solver/types.h"

namespace plumb {
class LocalMapper;
}

namespace plumb::loop {

constexpr std::size_t kMaxLoopPoints = 500;
constexpr std::size_t kMaxLoopLines = 100;

struct LoopPoint {
  Eigen::Vector3f P_cam = Eigen::Vector3f::Zero();
  Eigen::Vector2f px = Eigen::Vector2f::Zero();  // undistorted
  float u_right = 0;
  int8_t octave = 0;
};

struct LoopLine {
  Eigen::Vector3f l = Eigen::Vector3f::Zero();  // normalised 2D line (undistorted pixels)
  int8_t octave = 0;
  uint8_t num_samples = 0;
  std::array<Eigen::Vector3f, kMaxLineSamples> samples_cam{};
};

// A keyframe of the local map as local BA has it when the record is made (mapping frame).
struct LoopWindowPose {
  uint32_t id = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
};

struct LoopKeyframe {
  uint32_t id = 0;  // the map's keyframe id (grows forever)
  uint64_t frame_sequence = 0;
  double timestamp_s = 0;
  // First keyframe of a map segment: no odometry edge from a previous keyframe of the same map
  // (the closer links it to the previous record with a weak edge, see LoopCloserOptions).
  bool new_segment = false;
  uint32_t previous_id = 0;  // previous keyframe of the map (0: none)
  Eigen::Isometry3d T_previous_this = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();  // mapping frame, at creation
  // Covariance of T_previous_this (its right perturbation, the pose graph's edge error) from local
  // BA's joint marginal, calibrated (KeyframeUncertainty); the keyframe's marginal ([rho; phi],
  // left on T_cam_world) when no BA held both keyframes.
  Matrix6d covariance = Matrix6d::Zero();
  bool covariance_valid = false;
  // Every keyframe of the local map (this one included), as the BA that just ran left them: the
  // closer refreshes its odometry edges between keyframes still in the local map with these
  // (docs/LOOP.md "`--out` with loops: what is left"). Unordered.
  FixedVector<LoopWindowPose, kMaxMapKeyframes> window;

  FixedVector<LoopPoint, kMaxLoopPoints> points;
  FixedVector<Descriptor256, kMaxLoopPoints> point_descriptors;  // parallel to points
  FixedVector<LoopLine, kMaxLoopLines> lines;
  FixedVector<Descriptor256, kMaxLoopLines> line_descriptors;  // parallel to lines

  void clearFeatures() {
    points.clear();
    point_descriptors.clear();
    lines.clear();
    line_descriptors.clear();
  }
};

// What the LoopCloser stores of a record once the record has been queried: a keyframe is verified
// as the QUERY only when it arrives (the full LoopKeyframe is at hand then) and later only as a
// CANDIDATE, for which LoopVerifier::verify reads the point descriptors and 3D points and the line
// descriptors and line-guidance samples, and the octaves of both (the pixel noise of the 3D points
// and samples, propagated into the loop's covariance), nothing else. The samples of all lines share one array
// (line k's are [first_sample[k], first_sample[k] + num_samples[k])). Values are copied, not
// converted: verification against a LoopCandidate is bit-identical to the full record.
// 37.5 KB against 47.4 KB for the full record (docs/LOOP.md "Memory").
struct LoopCandidate {
  uint32_t id = 0;
  uint16_t num_points = 0;
  uint16_t num_lines = 0;
  std::array<Descriptor256, kMaxLoopPoints> point_descriptors{};
  std::array<Eigen::Vector3f, kMaxLoopPoints> P_cam{};  // camera frame
  std::array<int8_t, kMaxLoopPoints> point_octave{};
  std::array<Descriptor256, kMaxLoopLines> line_descriptors{};
  std::array<uint8_t, kMaxLoopLines> num_samples{};
  std::array<int8_t, kMaxLoopLines> line_octave{};
  std::array<uint16_t, kMaxLoopLines> first_sample{};
  std::array<Eigen::Vector3f, kMaxLoopLines * kMaxLineSamples> samples_cam{};  // camera frame
};

// The candidate part of a record. Allocation-free.
void makeLoopCandidate(const LoopKeyframe& record, LoopCandidate* out);

// The features of a record from a frame's features: the strongest keypoints with depth (response
// descending, index ascending on ties: deterministic) and the first lines with a 3D fit (the front
// end ranks lines best first). Allocation-free.
void fillLoopFeatures(const FrameFeatures& features, LoopKeyframe* out);

// The whole record for keyframe `keyframe_id`, just inserted by `mapper` from `request`: features,
// and odometry from the mapper's current poses (the keyframe before it in the map, the covariance
// of the local BA that ran at the insertion). Returns false when the keyframe is not in the map.
bool makeLoopKeyframe(const KeyframeRequest& request, uint32_t keyframe_id, bool new_segment,
                      const LocalMapper& mapper, LoopKeyframe* out);

}  // namespace plumb::loop
