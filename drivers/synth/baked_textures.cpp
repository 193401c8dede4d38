// Textures painted on first use (see baked_textures.h).
#include "drivers/synth/baked_textures.h"

#include <algorithm>

#include "drivers/synth/light_baking.h"
#include "platform/memory_residency.h"

namespace plumb::synth {

namespace {

constexpr size_t kAlignment = 64;  // each texture starts on a cache line

size_t aligned(size_t bytes) { return (bytes + kAlignment - 1) & ~(kAlignment - 1); }

size_t textureBytes(const TextureRecipe& recipe) { return aligned(static_cast<size_t>(recipe.rows) * recipe.cols * 3); }

// Below this, mapping the new faces' memory ahead is not worth a hand-over.
constexpr size_t kMinBytesToPopulate = size_t(256) << 10;

}  // namespace

BakedTextures::BakedTextures(const SceneModel& model, uint8_t* canvas_memory, size_t canvas_memory_bytes)
    : model_(model), textures_(model.textures.size()) {
  size_t canvas_bytes = 0, gain_bytes = 0, texture_bytes = 0;
  for (const TextureRecipe& recipe : model.textures) {
    canvas_bytes = std::max(canvas_bytes, aligned(PaintScratch::canvasBytes(recipe)));
    gain_bytes = std::max(gain_bytes, aligned(PaintScratch::gainBytes(recipe)));
    texture_bytes += textureBytes(recipe);
    light_scratch_.reserve(recipe.cols);
  }
  const bool lent_canvas = canvas_memory != nullptr && canvas_bytes > 0 && canvas_bytes <= canvas_memory_bytes;
  if (lent_canvas) scratch_.canvas = cv::Mat(1, static_cast<int>(canvas_bytes), CV_8U, canvas_memory);
  const size_t own_canvas_bytes = lent_canvas ? 0 : canvas_bytes;
  memory_ = HugePageBuffer(own_canvas_bytes + gain_bytes + texture_bytes);
  if (!memory_.data()) return;  // no block: painting allocates as it goes
  if (own_canvas_bytes) scratch_.canvas = cv::Mat(1, static_cast<int>(own_canvas_bytes), CV_8U, memory_.data());
  if (gain_bytes) scratch_.gain = cv::Mat(1, static_cast<int>(gain_bytes), CV_8U, memory_.data() + own_canvas_bytes);
  memory_used_ = scratch_bytes_ = own_canvas_bytes + gain_bytes;
}

void BakedTextures::PopulateJob::run(void* job) {
  const PopulateJob& j = *static_cast<const PopulateJob*>(job);
  (void)populateForWrite(j.data, j.bytes);
}

void BakedTextures::paint(int quad_index) {
  const SceneQuad& quad = model_.quads[quad_index];
  SurfaceTexture& texture = textures_[quad.texture];
  const TextureRecipe& recipe = model_.textures[quad.texture];
  if (memory_.data()) {
    texture.bgr = cv::Mat(recipe.rows, recipe.cols, CV_8UC3, memory_.data() + memory_used_);
    memory_used_ += textureBytes(recipe);
  }
  paintTexture(recipe, scratch_, texture.bgr);
  texture.texels_per_metre = recipe.texels_per_metre;
}

void BakedTextures::light(int quad_index) {
  const SceneQuad& quad = model_.quads[quad_index];
  SurfaceTexture& texture = textures_[quad.texture];
  bakeLighting(model_, quad, model_.textures[quad.texture].texels_per_metre, texture.bgr, light_scratch_);
}

void BakedTextures::prepare(int quad_index) {
  if (painted(quad_index)) return;
  paint(quad_index);
  light(quad_index);
}

void BakedTextures::prepareAll(const int* quads, int count, runtime::HelperThread* helper) {
  // Below this many texels in the pair, handing the lighting over costs more than it saves.
  constexpr long kMinTexelsToOverlap = 64 * 1024;
  auto texels = [&](int q) {
    const TextureRecipe& r = model_.textures[model_.quads[q].texture];
    return long(r.rows) * r.cols;
  };
  // The memory the new faces' texels will take (handed out in painting order, so one range):
  // the helper maps it while the first face is painted (the kernel only, no byte touched), and
  // the painting that follows does not stop for page faults.
  if (helper != nullptr && memory_.data()) {
    size_t need = 0;
    for (int i = 0; i < count; ++i) {
      if (!painted(quads[i])) need += textureBytes(model_.textures[model_.quads[quads[i]].texture]);
    }
    need = std::min(need, memory_.size() - memory_used_);
    if (need >= kMinBytesToPopulate) {
      helper->wait();  // populate_ may still be read by an earlier job
      populate_ = PopulateJob{memory_.data() + memory_used_, need};
      (void)helper->startJob(&PopulateJob::run, &populate_);
    }
  }
  int to_light = -1;  // painted, not yet lit
  for (int i = 0; i < count; ++i) {
    const int q = quads[i];
    if (painted(q)) continue;
    if (to_light >= 0 && helper != nullptr && texels(to_light) + texels(q) >= kMinTexelsToOverlap) {
      const int lit = to_light;
      helper->runBoth([&] { paint(q); }, [&] { light(lit); });
    } else {
      if (to_light >= 0) light(to_light);
      paint(q);
    }
    to_light = q;
  }
  if (to_light >= 0) light(to_light);
  if (helper != nullptr) helper->wait();  // the populate job, if no hand-over waited for it
}

}  // namespace plumb::synth
