#pragma once
// The synthetic room as the renderer sees it: a list of one-sided planar rectangles ("quads") in
// the world frame, each with its own texture (a recipe, painted when a frame first sees the quad:
// texture_recipe.h, baked_textures.h) and one light setup. Lighting is view-independent (Lambert),
// so light_baking.h multiplies it into a face's texture once, as it is painted, and rendering a
// pixel is a single texture lookup.
//
// Everything in the room is built from axis-aligned boxes (walls are the inside of one big box),
// so a quad is origin + two perpendicular edges. A quad is visible only from its front (the side
// its normal points to): closed boxes need no back faces, and faces flush with a wall or the
// floor never z-fight with it because they face away from every camera inside the room.
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "drivers/synth/texture_recipe.h"

namespace plumb::synth {

struct SceneQuad {
  Eigen::Vector3d origin_world;  // one corner
  Eigen::Vector3d axis_u_world;  // unit vector along the first edge
  Eigen::Vector3d axis_v_world;  // unit vector along the second edge
  Eigen::Vector3d normal_world;  // unit front normal
  double length_u = 0, length_v = 0;  // edge lengths in metres
  cv::Vec3f albedo_bgr;               // flat colour (0..255) of untextured faces
  int texture = -1;                   // index into SceneModel::textures; -1 until planLightMaps
};

struct SceneModel {
  std::vector<SceneQuad> quads;
  std::vector<TextureRecipe> textures;  // each quad its own (each face is lit on its own texels)
  Eigen::Vector3d room_min_world = Eigen::Vector3d::Zero();  // interior of the room
  Eigen::Vector3d room_max_world = Eigen::Vector3d::Zero();
  // A soft point light near the ceiling adds smooth gradients (no corners) across every face.
  Eigen::Vector3d lamp_world = Eigen::Vector3d::Zero();
  float lamp_strength = 0.35f;      // added shade at 1 m, falling off as 1 / (1 + d^2 / 4)
  Eigen::Vector3d sun_dir_world = Eigen::Vector3d(0.4, 0.25, -0.88).normalized();  // light travels along it
  float ambient = 0.55f, sun_strength = 0.35f;
};

// Faces of an axis-aligned box, by their outward normal.
enum BoxFace : unsigned {
  kFaceMinX = 1u << 0, kFaceMaxX = 1u << 1, kFaceMinY = 1u << 2,
  kFaceMaxY = 1u << 3, kFaceMinZ = 1u << 4, kFaceMaxZ = 1u << 5,
  kAllFaces = 63u,
};

// Appends the faces in `faces` of the box [min, max]; inward = true makes them face the inside
// (the room's walls). Returns the index of the first quad appended.
int addBox(SceneModel& model, const Eigen::Vector3d& min_world, const Eigen::Vector3d& max_world,
           const cv::Vec3f& albedo_bgr, unsigned faces = kAllFaces, bool inward = false);

}  // namespace plumb::synth
