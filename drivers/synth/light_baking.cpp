// Lighting baked into face textures (see light_baking.h).
#include "drivers/synth/light_baking.h"

#include <algorithm>
#include <cmath>

namespace plumb::synth {
namespace {

float lightAt(const SceneModel& model, const SceneQuad& quad, const Eigen::Vector3d& P_world) {
  const double sun = std::max(0.0, -quad.normal_world.dot(model.sun_dir_world));
  const Eigen::Vector3d to_lamp = model.lamp_world - P_world;
  const double distance2 = to_lamp.squaredNorm();
  const double cosine = std::max(0.0, quad.normal_world.dot(to_lamp)) / std::sqrt(distance2);
  return static_cast<float>(model.ambient + model.sun_strength * sun +
                            model.lamp_strength * cosine / (1.0 + distance2 / 4.0));
}

}  // namespace

void bakeLighting(SceneModel& model, double lightmap_texels_per_metre) {
  for (SceneQuad& quad : model.quads) {
    if (quad.texture < 0) {  // a flat face: a small light map in its colour
      SurfaceTexture lightmap;
      lightmap.texels_per_metre = lightmap_texels_per_metre;
      const int cols = std::max(2, static_cast<int>(std::ceil(quad.length_u * lightmap_texels_per_metre)));
      const int rows = std::max(2, static_cast<int>(std::ceil(quad.length_v * lightmap_texels_per_metre)));
      lightmap.bgr.create(rows, cols, CV_8UC3);
      lightmap.bgr.setTo(cv::Scalar(quad.albedo_bgr[0], quad.albedo_bgr[1], quad.albedo_bgr[2]));
      quad.texture = static_cast<int>(model.textures.size());
      model.textures.push_back(lightmap);
    }
    SurfaceTexture& texture = model.textures[quad.texture];
    cv::Mat& bgr = texture.bgr;
    for (int y = 0; y < bgr.rows; ++y) {
      cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
      // Texel centres, clamped onto the face (light maps may overhang its far edges).
      const double t = std::min((y + 0.5) / texture.texels_per_metre, quad.length_v);
      for (int x = 0; x < bgr.cols; ++x) {
        const double s = std::min((x + 0.5) / texture.texels_per_metre, quad.length_u);
        const float light = lightAt(model, quad, quad.origin_world + quad.axis_u_world * s + quad.axis_v_world * t);
        for (int k = 0; k < 3; ++k) row[x][k] = cv::saturate_cast<uchar>(row[x][k] * light);
      }
    }
  }
}

}  // namespace plumb::synth
