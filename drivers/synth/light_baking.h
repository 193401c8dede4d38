#pragma once
// Bakes the room's view-independent lighting into a face's texture, once, when it is painted:
//   light(P) = ambient + sun_strength * max(0, -n . sun_dir)
//            + lamp_strength * max(0, n . (lamp - P) / |lamp - P|) / (1 + |lamp - P|^2 / 4)
// The sun term makes the faces of a box differ in brightness (strong edges even between equally
// coloured faces); the lamp adds smooth gradients that carry no corners. Untextured faces get a
// coarse light map (albedo x light) so that they too are a single bilinear lookup at render time.
#include <vector>

#include <opencv2/core.hpp>

#include "drivers/synth/scene_model.h"

namespace plumb::synth {

// Gives every quad that has no texture a light map recipe: its flat albedo at
// lightmap_texels_per_metre. Afterwards every quad has a texture.
void planLightMaps(SceneModel& model, double lightmap_texels_per_metre);

// Row buffers of bakeLighting. Sized once for the widest texture, baking allocates nothing (a
// face first seen in a steady run must not allocate per frame).
struct LightScratch {
  void reserve(int cols);
  std::vector<double> column_term;
  std::vector<float> row_light;
};

// Multiplies the light on `quad` into bgr, its painted texture at texels_per_metre. Axis-aligned
// quads (u and v along +world axes, as addBox makes them all) take a separable fast path with
// the same result to the bit; any other quad takes bakeLightingPerTexel.
void bakeLighting(const SceneModel& model, const SceneQuad& quad, double texels_per_metre, cv::Mat& bgr,
                  LightScratch& scratch);

// The formula above evaluated texel by texel, for any quad (the oracle of the fast path).
void bakeLightingPerTexel(const SceneModel& model, const SceneQuad& quad, double texels_per_metre, cv::Mat& bgr);

}  // namespace plumb::synth
