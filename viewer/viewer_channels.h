#pragma once
// The channels plumb's viewer advertises (docs/VIEWER.md has the table and the Foxglove panels
// that show each). Indices into viewerChannels(); channel ids on the wire are index + 1.
#include <cstddef>
#include <vector>

#include "viewer/foxglove_server.h"

namespace plumb::viewer {

enum ViewerChannel : std::size_t {
  kCameraPose,       // /plumb/camera_pose   foxglove.PoseInFrame     each tracked frame, as tracked
  kCameraTransform,  // /tf                  foxglove.FrameTransform  world -> camera, same poses
  kOutputPose,       // /plumb/output_pose   foxglove.PoseInFrame     each line of the trajectory file
  kTrajectory,       // /plumb/trajectory    foxglove.SceneUpdate     output + tracked tail (+ ground truth)
  kLoops,            // /plumb/loops         foxglove.SceneUpdate     accepted loop edges
  kMapPoints,        // /plumb/map_points    foxglove.PointCloud      local map points
  kMapLines,         // /plumb/map_lines     foxglove.SceneUpdate     line landmarks
  kKeyframes,        // /plumb/keyframes     foxglove.SceneUpdate     keyframe frusta
  kImage,            // /plumb/image         foxglove.CompressedImage colour image, downscaled, JPEG
  kStatus,           // /plumb/status        plumb.Status             state, inliers, latency, drops, loops
  kChannelCount
};

std::vector<FoxgloveChannel> viewerChannels();

}  // namespace plumb::viewer
