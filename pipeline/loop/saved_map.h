#pragma once
// SavedMap: what a map file holds (docs/LOOP.md "Map files"), as a plain value: the camera the map
// was made with, the loop closer's keyframe records with their pose-graph nodes, and its loop
// edges. Made by LoopCloser::exportMap at the end of a run (`plumb run --save-map`), turned into
// bytes by saved_map_codec.h, put in a checksummed file by drivers/mapfile/, and given back to a
// new run (`--load-map`) that relocalizes into it (LoopCloser::restoreMap, OdometrySystem's loaded
// keyframes).
//
// The keyframe database is NOT stored: its words are a fixed function of the descriptors
// (place_words.h), so restoreMap rebuilds it from the records' ORB and LBD descriptors (a few
// milliseconds for 256 keyframes) and the file cannot hold a database that disagrees with them.
// Landmarks are not stored either: each record carries its keypoints' 3D points (camera frame,
// from depth) and its lines' samples, which is what relocalization and loop verification use.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "pipeline/loop/loop_keyframe.h"
#include "sensor/camera.h"
#include "solver/types.h"

namespace plumb::loop {

// One keyframe: its loop record (features, odometry, covariance) and its pose-graph node.
struct SavedKeyframe {
  LoopKeyframe record;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();  // the graph's (optimised) pose
  bool has_edge = false;  // an odometry edge from the previous keyframe in the file
  Eigen::Isometry3d T_previous_this = Eigen::Isometry3d::Identity();
  Matrix6d edge_covariance = Matrix6d::Identity();
  double edge_length_m = 0;
  uint32_t previous_map_id = 0;
};

struct SavedLoopEdge {
  uint32_t candidate_id = 0;
  uint32_t query_id = 0;
  Eigen::Isometry3d T_candidate_query = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Identity();
};

struct SavedMap {
  PinholeCamera camera;
  // Ascending ids. Each SavedKeyframe is ~52 KB (a LoopKeyframe), so they are held by pointer: a
  // vector of them never copies records when it grows.
  std::vector<std::unique_ptr<SavedKeyframe>> keyframes;
  std::vector<SavedLoopEdge> loop_edges;

  uint32_t maxKeyframeId() const { return keyframes.empty() ? 0 : keyframes.back()->record.id; }
};

// Empty when `run` can use a map made with `saved`; otherwise which parameter differs (intrinsics,
// distortion, image size, depth factor, baseline), with both values.
std::string cameraMismatch(const PinholeCamera& saved, const PinholeCamera& run);

}  // namespace plumb::loop
