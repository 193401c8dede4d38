// Lighting baked into face textures (see light_baking.h).
#include "drivers/synth/light_baking.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>

#include "drivers/synth/texel_gain.h"

namespace plumb::synth {
namespace {

// The light formula of one quad with its per-quad terms worked out once. Each texel's light is
// the same sequence of double operations as the plain Eigen formula (light_baking.h): per
// coordinate P = (origin + u * s) + v * t, sums of three products left to right, so the SIMD
// and scalar paths give the same bits (no FMA contraction on the default x86-64 target).
struct QuadLight {
  double base;           // ambient + sun_strength * max(0, -n . sun_dir)
  double lamp_strength;
  double origin[3], u[3], n[3], lamp[3];
  double v_t[3];         // v * t of the current texel row

  QuadLight(const SceneModel& model, const SceneQuad& quad) {
    const double sun = std::max(0.0, -quad.normal_world.dot(model.sun_dir_world));
    base = model.ambient + model.sun_strength * sun;
    lamp_strength = model.lamp_strength;
    for (int i = 0; i < 3; ++i) {
      origin[i] = quad.origin_world[i];
      u[i] = quad.axis_u_world[i];
      n[i] = quad.normal_world[i];
      lamp[i] = model.lamp_world[i];
      v_t[i] = 0;
    }
  }

  float at(double s) const {
    double to_lamp[3];
    for (int i = 0; i < 3; ++i) to_lamp[i] = lamp[i] - ((origin[i] + u[i] * s) + v_t[i]);
    const double distance2 = (to_lamp[0] * to_lamp[0] + to_lamp[1] * to_lamp[1]) + to_lamp[2] * to_lamp[2];
    const double facing = (n[0] * to_lamp[0] + n[1] * to_lamp[1]) + n[2] * to_lamp[2];
    const double cosine = std::max(0.0, facing) / std::sqrt(distance2);
    return static_cast<float>(base + lamp_strength * cosine / (1.0 + distance2 / 4.0));
  }

#if CV_SIMD128_64F
  cv::v_float64x2 at(const cv::v_float64x2& s) const {
    using cv::v_setall_f64;
    cv::v_float64x2 to_lamp[3];
    for (int i = 0; i < 3; ++i)
      to_lamp[i] = v_setall_f64(lamp[i]) - ((v_setall_f64(origin[i]) + v_setall_f64(u[i]) * s) + v_setall_f64(v_t[i]));
    const cv::v_float64x2 distance2 = (to_lamp[0] * to_lamp[0] + to_lamp[1] * to_lamp[1]) + to_lamp[2] * to_lamp[2];
    const cv::v_float64x2 facing = (v_setall_f64(n[0]) * to_lamp[0] + v_setall_f64(n[1]) * to_lamp[1]) +
                                   v_setall_f64(n[2]) * to_lamp[2];
    const cv::v_float64x2 cosine = cv::v_max(v_setall_f64(0.0), facing) / cv::v_sqrt(distance2);
    return v_setall_f64(base) +
           v_setall_f64(lamp_strength) * cosine / (v_setall_f64(1.0) + distance2 / v_setall_f64(4.0));
  }
#endif
};

// Lights of one texel row: s = min((x + 0.5) / texels_per_metre, length_u) for x < count.
void lightRow(const QuadLight& light, double texels_per_metre, double length_u, int count, float* out) {
  int x = 0;
#if CV_SIMD128_64F
  const cv::v_float64x2 tpm = cv::v_setall_f64(texels_per_metre), max_s = cv::v_setall_f64(length_u);
  for (; x + 4 <= count; x += 4) {
    const cv::v_float64x2 s0 = cv::v_min(cv::v_float64x2(x + 0.5, x + 1.5) / tpm, max_s);
    const cv::v_float64x2 s1 = cv::v_min(cv::v_float64x2(x + 2.5, x + 3.5) / tpm, max_s);
    cv::v_store(out + x, cv::v_cvt_f32(light.at(s0), light.at(s1)));
  }
#endif
  for (; x < count; ++x) out[x] = light.at(std::min((x + 0.5) / texels_per_metre, length_u));
}

}  // namespace

void planLightMaps(SceneModel& model, double lightmap_texels_per_metre) {
  for (SceneQuad& quad : model.quads) {
    if (quad.texture >= 0) continue;
    quad.texture = static_cast<int>(model.textures.size());
    model.textures.push_back(flatTextureRecipe(quad.length_u, quad.length_v, lightmap_texels_per_metre, quad.albedo_bgr));
  }
}

void bakeLighting(const SceneModel& model, const SceneQuad& quad, double texels_per_metre, cv::Mat& bgr) {
  QuadLight light(model, quad);
  std::vector<float> row_light(bgr.cols);
  for (int y = 0; y < bgr.rows; ++y) {
    // Texel centres, clamped onto the face (light maps may overhang its far edges).
    const double t = std::min((y + 0.5) / texels_per_metre, quad.length_v);
    for (int i = 0; i < 3; ++i) light.v_t[i] = quad.axis_v_world[i] * t;
    lightRow(light, texels_per_metre, quad.length_u, bgr.cols, row_light.data());
    multiplyTexels(bgr.ptr<cv::Vec3b>(y), row_light.data(), bgr.cols);
  }
}

}  // namespace plumb::synth
