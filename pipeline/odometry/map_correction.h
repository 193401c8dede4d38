#pragma once
// MapCorrection: what loop closing sends back to the mapping side (docs/LOOP.md "Correction").
// "Keyframe `keyframe_id` belongs at T_world_cam." The mapping side turns it into ONE rigid motion
// C = T_world_cam * T_world_cam_current^-1 applied to every keyframe and landmark of its local map
// (LocalMapper::applyCorrection), so the local map stays internally exactly as consistent as it was
// and lands where the pose graph put the keyframe. A plain value, sent through a
// runtime::LatestSnapshot (the newest correction wins; versions count corrections).
#include <Eigen/Geometry>
#include <cstdint>

namespace plumb {

struct MapCorrection {
  uint32_t keyframe_id = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  // The loop that caused it: the old keyframe the query keyframe was matched to, at its optimised
  // pose (0: none). Only viewers read it (the loop edge they draw); the mapping side ignores it.
  uint32_t loop_candidate_id = 0;
  Eigen::Isometry3d T_world_candidate = Eigen::Isometry3d::Identity();
};

}  // namespace plumb
