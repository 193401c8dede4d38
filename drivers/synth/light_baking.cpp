// Lighting baked into face textures (see light_baking.h).
//
// Every quad is axis-aligned (addBox makes them all), which makes the light formula separable:
// with u = e_{a_u}, v = e_{a_v} and n = +-e_{a_n},
//   P = (origin + u s) + v t   has   P[a_u] = origin[a_u] + s,  P[a_v] = origin[a_v] + t,
//                                    P[a_n] = origin[a_n],
//   n . (lamp - P) = n[a_n] (lamp[a_n] - origin[a_n])        the same for every texel,
//   |lamp - P|^2 = sum over the axes, in axis order, of one term per column (a_u), one per row
//                  (a_v) and a constant (a_n).
// The other products are +-0, so these are the values the general formula computes, to the bit
// (signs of zero aside, which cannot reach the result). A texel then costs two additions, a square
// root, two divisions and a conversion: a few instructions with SIMD, instead of ~50 for the plain
// per-texel Eigen formula (which the tests keep as the oracle).
#include "drivers/synth/light_baking.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>

#include "drivers/synth/texel_gain.h"

namespace plumb::synth {
namespace {

// The world axis a unit vector runs along (+-1 in one coordinate, 0 in the others), or -1.
int worldAxisOf(const Eigen::Vector3d& direction) {
  int axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (direction[i] == 0) continue;
    if (axis >= 0 || std::abs(direction[i]) != 1) return -1;
    axis = i;
  }
  return axis;
}

// The plain formula of light_baking.h at one point.
float lightAt(const SceneModel& model, const SceneQuad& quad, const Eigen::Vector3d& P_world) {
  const double sun = std::max(0.0, -quad.normal_world.dot(model.sun_dir_world));
  const Eigen::Vector3d to_lamp = model.lamp_world - P_world;
  const double distance2 = to_lamp.squaredNorm();
  const double cosine = std::max(0.0, quad.normal_world.dot(to_lamp)) / std::sqrt(distance2);
  return static_cast<float>(model.ambient + model.sun_strength * sun +
                            model.lamp_strength * cosine / (1.0 + distance2 / 4.0));
}

// Texel centres, clamped onto the face (light maps may overhang its far edges).
double texelCentre(int i, double texels_per_metre, double length) {
  return std::min((i + 0.5) / texels_per_metre, length);
}

// light = float(base + lamp_strength * (facing / sqrt(d2)) / (1 + d2 / 4)),
// d2 = (column_term + row_first) + row_second. d2 * 0.25 is d2 / 4 to the bit (a power of two),
// one division fewer.
struct TexelLight {
  double base, lamp_strength, facing;
  double row_first = 0, row_second = 0;

  float at(double column_term) const {
    const double distance2 = (column_term + row_first) + row_second;
    const double cosine = facing / std::sqrt(distance2);
    return static_cast<float>(base + lamp_strength * cosine / (1.0 + distance2 * 0.25));
  }
#if CV_SIMD128_64F
  cv::v_float64x2 at(const cv::v_float64x2& column_term) const {
    using cv::v_setall_f64;
    const cv::v_float64x2 distance2 = (column_term + v_setall_f64(row_first)) + v_setall_f64(row_second);
    const cv::v_float64x2 cosine = v_setall_f64(facing) / cv::v_sqrt(distance2);
    return v_setall_f64(base) +
           v_setall_f64(lamp_strength) * cosine / (v_setall_f64(1.0) + distance2 * v_setall_f64(0.25));
  }
#endif

  void row(const double* column_terms, int count, float* out) const {
    int x = 0;
#if CV_SIMD128_64F
    for (; x + 4 <= count; x += 4)
      cv::v_store(out + x, cv::v_cvt_f32(at(cv::v_load(column_terms + x)), at(cv::v_load(column_terms + x + 2))));
#endif
    for (; x < count; ++x) out[x] = at(column_terms[x]);
  }
};

}  // namespace

void planLightMaps(SceneModel& model, double lightmap_texels_per_metre) {
  for (SceneQuad& quad : model.quads) {
    if (quad.texture >= 0) continue;
    quad.texture = static_cast<int>(model.textures.size());
    model.textures.push_back(flatTextureRecipe(quad.length_u, quad.length_v, lightmap_texels_per_metre, quad.albedo_bgr));
  }
}

void bakeLightingPerTexel(const SceneModel& model, const SceneQuad& quad, double texels_per_metre, cv::Mat& bgr) {
  for (int y = 0; y < bgr.rows; ++y) {
    cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    const double t = texelCentre(y, texels_per_metre, quad.length_v);
    for (int x = 0; x < bgr.cols; ++x) {
      const double s = texelCentre(x, texels_per_metre, quad.length_u);
      const float light = lightAt(model, quad, quad.origin_world + quad.axis_u_world * s + quad.axis_v_world * t);
      for (int k = 0; k < 3; ++k) row[x][k] = cv::saturate_cast<uchar>(row[x][k] * light);
    }
  }
}

void LightScratch::reserve(int cols) {
  if (static_cast<int>(column_term.size()) < cols) column_term.resize(cols);
  if (static_cast<int>(row_light.size()) < cols) row_light.resize(cols);
}

void bakeLighting(const SceneModel& model, const SceneQuad& quad, double texels_per_metre, cv::Mat& bgr,
                  LightScratch& scratch) {
  const int a_u = worldAxisOf(quad.axis_u_world), a_v = worldAxisOf(quad.axis_v_world);
  const int a_n = worldAxisOf(quad.normal_world);
  const bool separable = a_u >= 0 && a_v >= 0 && a_n >= 0 && a_u != a_v && a_u != a_n && a_v != a_n &&
                         quad.axis_u_world[a_u] == 1 && quad.axis_v_world[a_v] == 1;
  if (!separable) return bakeLightingPerTexel(model, quad, texels_per_metre, bgr);

  const Eigen::Vector3d& lamp = model.lamp_world;
  const Eigen::Vector3d& origin = quad.origin_world;
  TexelLight light;
  const double sun = std::max(0.0, -quad.normal_world.dot(model.sun_dir_world));
  light.base = model.ambient + model.sun_strength * sun;
  light.lamp_strength = model.lamp_strength;
  light.facing = quad.normal_world[a_n] * (lamp[a_n] - origin[a_n]);
  scratch.reserve(bgr.cols);
  float* row_light = scratch.row_light.data();
  double* column_term = scratch.column_term.data();
  // Faces turned from the lamp, or no lamp: the lamp term is 0 and every texel gets the base.
  const bool lamp_reaches = light.facing > 0 && light.lamp_strength != 0;
  if (!lamp_reaches) std::fill(row_light, row_light + bgr.cols, static_cast<float>(light.base));

  for (int x = 0; x < bgr.cols; ++x) {
    const double s = texelCentre(x, texels_per_metre, quad.length_u);
    const double to_lamp = lamp[a_u] - (origin[a_u] + s);
    column_term[x] = to_lamp * to_lamp;
  }
  const double to_lamp_n = lamp[a_n] - origin[a_n];
  double axis_term[3];
  axis_term[a_n] = to_lamp_n * to_lamp_n;
  for (int y = 0; y < bgr.rows; ++y) {
    if (lamp_reaches) {
      const double t = texelCentre(y, texels_per_metre, quad.length_v);
      const double to_lamp_v = lamp[a_v] - (origin[a_v] + t);
      axis_term[a_v] = to_lamp_v * to_lamp_v;
      // d2 = (term0 + term1) + term2, with the column's term where a_u stands.
      if (a_u == 2) {
        light.row_first = axis_term[0] + axis_term[1];
        light.row_second = 0.0;
      } else {
        light.row_first = axis_term[1 - a_u];
        light.row_second = axis_term[2];
      }
      light.row(column_term, bgr.cols, row_light);
    }
    multiplyTexels(bgr.ptr<cv::Vec3b>(y), row_light, bgr.cols);
  }
}

}  // namespace plumb::synth
