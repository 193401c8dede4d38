#pragma once
// JSON encodings of the Foxglove messages the viewer sends (schemas: viewer/foxglove_schemas.h).
// Server thread only (they build strings). Poses are T_world_cam (camera to world, TUM), frames
// "world" and "camera"; times are the frames' sensor timestamps in seconds.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plumb::viewer {

struct Rgba {
  float r = 1, g = 1, b = 1, a = 1;
};

// One foxglove.LinePrimitive.
struct LinePrimitive {
  enum Type { kStrip = 0, kLoop = 1, kList = 2 };
  Type type = kStrip;
  double thickness_px = 2;  // scale invariant (pixels)
  Rgba color;
  std::vector<Eigen::Vector3f> points;
  std::vector<Rgba> colors;  // empty, or one per point (then `color` is ignored)
};

// One foxglove.SceneEntity made of line primitives.
struct LineEntity {
  std::string id;
  std::vector<LinePrimitive> lines;
};

std::string poseInFrameJson(double timestamp_s, const Eigen::Vector3d& t_world_cam, const Eigen::Quaterniond& q_world_cam);
std::string frameTransformJson(double timestamp_s, const Eigen::Vector3d& t_world_cam,
                               const Eigen::Quaterniond& q_world_cam);
// Replaces every entity of the channel (a deletion of all, then `entities`).
std::string sceneUpdateJson(double timestamp_s, const std::vector<LineEntity>& entities);
// x, y, z float32 per point, little-endian, base64.
std::string pointCloudJson(double timestamp_s, const std::vector<Eigen::Vector3f>& points_world);
std::string compressedImageJson(double timestamp_s, const std::vector<uint8_t>& jpeg);

std::string base64(const uint8_t* bytes, std::size_t size);

// The camera's viewing frustum as a line list (pyramid apex at the camera centre, base `depth_m`
// in front), for keyframes.
void appendFrustum(const Eigen::Vector3f& t_world_cam, const Eigen::Quaternionf& q_world_cam, float depth_m,
                   std::vector<Eigen::Vector3f>* line_list);

}  // namespace plumb::viewer
