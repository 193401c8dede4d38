#pragma once
// Seeded procedural textures for the "textured" presets: a base colour with low-frequency shading
// noise, blobs, checker patches and (on walls) posters. They give a corner detector plenty of
// stable corners at every distance in the room. Textures are band-limited (a light blur) so that
// bilinear sampling from 1 m to 6 m neither aliases nor looks blocky.
//
// Planning makes every random draw of a texture (cheap) and returns its recipe; paintTexture
// (texture_recipe.h) turns the recipe into texels when a frame first needs them.
#include <opencv2/core.hpp>

#include "drivers/synth/synth_random.h"
#include "drivers/synth/texture_recipe.h"

namespace plumb::synth {

enum class TextureStyle {
  kWall,     // posters, blobs, checker patches, soft stains
  kFloor,    // tiles with grout lines, speckles
  kObject,   // furniture faces: stripes, blobs, labels
  kRug,      // bold geometric pattern
  kCeiling,  // faint noise only (rarely seen)
};

// The recipe of a texture of width_m x height_m metres (width along the quad's u edge) at
// texels_per_metre. Draws from rng exactly as many numbers as painting straight away used to.
TextureRecipe planSurfaceTexture(double width_m, double height_m, double texels_per_metre,
                                 TextureStyle style, const cv::Vec3f& base_bgr, SplitMix64& rng);

}  // namespace plumb::synth
