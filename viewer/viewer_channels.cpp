#include "viewer/viewer_channels.h"

#include "viewer/foxglove_schemas.h"

namespace plumb::viewer {

std::vector<FoxgloveChannel> viewerChannels() {
  std::vector<FoxgloveChannel> c(kChannelCount);
  c[kCameraPose] = {"/plumb/camera_pose", "foxglove.PoseInFrame", poseInFrameSchema()};
  c[kCameraTransform] = {"/tf", "foxglove.FrameTransform", frameTransformSchema()};
  c[kOutputPose] = {"/plumb/output_pose", "foxglove.PoseInFrame", poseInFrameSchema()};
  c[kTrajectory] = {"/plumb/trajectory", "foxglove.SceneUpdate", sceneUpdateSchema()};
  c[kLoops] = {"/plumb/loops", "foxglove.SceneUpdate", sceneUpdateSchema()};
  c[kMapPoints] = {"/plumb/map_points", "foxglove.PointCloud", pointCloudSchema()};
  c[kMapLines] = {"/plumb/map_lines", "foxglove.SceneUpdate", sceneUpdateSchema()};
  c[kKeyframes] = {"/plumb/keyframes", "foxglove.SceneUpdate", sceneUpdateSchema()};
  c[kImage] = {"/plumb/image", "foxglove.CompressedImage", compressedImageSchema()};
  c[kStatus] = {"/plumb/status", "plumb.Status", runStatusSchema()};
  return c;
}

}  // namespace plumb::viewer
