// Textures painted on first use (see baked_textures.h).
#include "drivers/synth/baked_textures.h"

#include <algorithm>

#include "drivers/synth/light_baking.h"

namespace plumb::synth {

namespace {

constexpr size_t kAlignment = 64;  // each texture starts on a cache line

size_t aligned(size_t bytes) { return (bytes + kAlignment - 1) & ~(kAlignment - 1); }

size_t textureBytes(const TextureRecipe& recipe) { return aligned(static_cast<size_t>(recipe.rows) * recipe.cols * 3); }

// Below this many texels in all, sharing the faces costs more than it saves.
constexpr long kMinTexelsToShare = 64 * 1024;

}  // namespace

BakedTextures::BakedTextures(const SceneModel& model, uint8_t* canvas_memory, size_t canvas_memory_bytes)
    : model_(model), textures_(model.textures.size()), taken_(model.textures.size(), 0) {
  size_t canvas_bytes = 0, gain_bytes = 0, texture_bytes = 0;
  for (const TextureRecipe& recipe : model.textures) {
    canvas_bytes = std::max(canvas_bytes, aligned(PaintScratch::canvasBytes(recipe)));
    gain_bytes = std::max(gain_bytes, aligned(PaintScratch::gainBytes(recipe)));
    texture_bytes += textureBytes(recipe);
    for (LightScratch& l : light_scratch_) l.reserve(recipe.cols);
  }
  for (std::vector<int>& share : share_) share.reserve(model.quads.size());
  // Painter 0 (the caller) draws in the lent canvas when it is large enough; painter 1 (the
  // helper) always has its own.
  const bool lent_canvas = canvas_memory != nullptr && canvas_bytes > 0 && canvas_bytes <= canvas_memory_bytes;
  if (lent_canvas) scratch_[0].canvas = cv::Mat(1, static_cast<int>(canvas_bytes), CV_8U, canvas_memory);
  const size_t own_canvas_bytes = lent_canvas ? 0 : canvas_bytes;
  scratch_bytes_ = own_canvas_bytes + 2 * gain_bytes + canvas_bytes;
  memory_ = HugePageBuffer(scratch_bytes_ + texture_bytes);
  if (!memory_.data()) return;  // no block: painting allocates as it goes
  uint8_t* next = memory_.data();
  auto view = [&next](size_t bytes) {
    cv::Mat m = bytes ? cv::Mat(1, static_cast<int>(bytes), CV_8U, next) : cv::Mat();
    next += bytes;
    return m;
  };
  if (own_canvas_bytes) scratch_[0].canvas = view(own_canvas_bytes);
  scratch_[0].gain = view(gain_bytes);
  scratch_[1].canvas = view(canvas_bytes);
  scratch_[1].gain = view(gain_bytes);
  memory_used_ = scratch_bytes_;
}

void BakedTextures::take(int quad_index) {
  const int t = model_.quads[quad_index].texture;
  taken_[t] = 1;
  if (!memory_.data()) return;  // painting allocates
  const TextureRecipe& recipe = model_.textures[t];
  textures_[t].bgr = cv::Mat(recipe.rows, recipe.cols, CV_8UC3, memory_.data() + memory_used_);
  memory_used_ += textureBytes(recipe);
}

void BakedTextures::paintAndLight(int quad_index, int k) {
  const SceneQuad& quad = model_.quads[quad_index];
  SurfaceTexture& texture = textures_[quad.texture];
  const TextureRecipe& recipe = model_.textures[quad.texture];
  paintTexture(recipe, scratch_[k], texture.bgr);
  bakeLighting(model_, quad, recipe.texels_per_metre, texture.bgr, light_scratch_[k]);
  texture.texels_per_metre = recipe.texels_per_metre;
}

void BakedTextures::prepare(int quad_index) {
  if (painted(quad_index)) return;
  take(quad_index);
  paintAndLight(quad_index, 0);
}

int BakedTextures::prepareAll(const int* quads, int count, runtime::HelperThread* helper) {
  // Memory first, in list order; then the faces go to whichever painter has fewer texels so far
  // (list order breaks ties: the same split every run, not that the split could change a texel).
  long load[2] = {0, 0};
  share_[0].clear();
  share_[1].clear();
  for (int i = 0; i < count; ++i) {
    const int q = quads[i];
    if (painted(q)) continue;
    take(q);
    const TextureRecipe& r = model_.textures[model_.quads[q].texture];
    const int k = load[1] < load[0] ? 1 : 0;
    share_[k].push_back(q);
    load[k] += long(r.rows) * r.cols;
  }
  auto paintShare = [this](int k) {
    for (int q : share_[k]) paintAndLight(q, k);
  };
  if (helper != nullptr && !share_[1].empty() && load[0] + load[1] >= kMinTexelsToShare) {
    helper->runBoth([&] { paintShare(0); }, [&] { paintShare(1); });
  } else {
    paintShare(0);
    paintShare(1);
  }
  return static_cast<int>(share_[0].size() + share_[1].size());
}

}  // namespace plumb::synth
