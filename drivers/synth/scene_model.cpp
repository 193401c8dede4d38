// Box -> quads for the synthetic room (see scene_model.h).
#include "drivers/synth/scene_model.h"

namespace plumb::synth {

int addBox(SceneModel& model, const Eigen::Vector3d& min_world, const Eigen::Vector3d& max_world,
           const cv::Vec3f& albedo_bgr, unsigned faces, bool inward) {
  const int first = static_cast<int>(model.quads.size());
  const Eigen::Vector3d size = max_world - min_world;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {  // 0: the min face, 1: the max face
      if (!(faces & (1u << (2 * axis + side)))) continue;
      // The two in-plane axes, in cyclic order so u x v points along +axis.
      const int a_u = (axis + 1) % 3, a_v = (axis + 2) % 3;
      SceneQuad quad;
      quad.origin_world = min_world;
      if (side == 1) quad.origin_world[axis] = max_world[axis];
      quad.axis_u_world = Eigen::Vector3d::Unit(a_u);
      quad.axis_v_world = Eigen::Vector3d::Unit(a_v);
      quad.length_u = size[a_u];
      quad.length_v = size[a_v];
      const double outward = side == 1 ? 1.0 : -1.0;
      quad.normal_world = Eigen::Vector3d::Unit(axis) * (inward ? -outward : outward);
      quad.albedo_bgr = albedo_bgr;
      model.quads.push_back(quad);
    }
  }
  return first;
}

}  // namespace plumb::synth
