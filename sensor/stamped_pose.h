#pragma once
// StampedPose: one sample of a camera trajectory. Part of the drivers/pipeline contract like the
// rest of sensor/: the pipeline's finished frames become StampedPoses
// (pipeline/odometry/odometry_trajectory.h: toStampedPose) and drivers/trajectory reads and
// writes them as TUM trajectory files (ground truth, estimates).
#include <Eigen/Geometry>

namespace plumb {

struct StampedPose {
  double timestamp = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  bool valid = true;  // false: the frame had no pose (written as `# <timestamp> lost`)
  bool dropped = false;  // with !valid: the frame was never processed (real-time drop), `# <timestamp> dropped`
};

}  // namespace plumb
