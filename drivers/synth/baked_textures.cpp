// Textures painted on first use (see baked_textures.h).
#include "drivers/synth/baked_textures.h"

#include "drivers/synth/light_baking.h"

namespace plumb::synth {

BakedTextures::BakedTextures(const SceneModel& model) : model_(model), textures_(model.textures.size()) {
  for (const TextureRecipe& recipe : model.textures) scratch_.reserveFor(recipe);
}

void BakedTextures::prepare(int quad_index) {
  const SceneQuad& quad = model_.quads[quad_index];
  SurfaceTexture& texture = textures_[quad.texture];
  if (!texture.bgr.empty()) return;
  const TextureRecipe& recipe = model_.textures[quad.texture];
  paintTexture(recipe, scratch_, texture.bgr);
  bakeLighting(model_, quad, recipe.texels_per_metre, texture.bgr);
  texture.texels_per_metre = recipe.texels_per_metre;
}

void BakedTextures::prepareAll() {
  for (int q = 0; q < static_cast<int>(model_.quads.size()); ++q) prepare(q);
}

}  // namespace plumb::synth
