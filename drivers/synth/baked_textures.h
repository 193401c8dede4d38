#pragma once
// The painted, lit textures of a scene's quads, made when a frame first needs them and kept.
//
// Painting and lighting every face up front cost ~1.5 G instructions (~150 ms) before the first
// frame, most of it on faces that frame does not see. A texture depends only on its recipe and its
// quad (never on when it is painted or what was painted before), so painting on first use gives
// the same texels, and so the same frames, as painting everything at once. Not thread-safe: it
// belongs to one FrameRenderer, which is itself used by one thread at a time (prepareAll hands
// half of its faces to the renderer's helper thread and returns when both halves are done).
#include <vector>

#include <opencv2/core.hpp>

#include "drivers/synth/light_baking.h"
#include "drivers/synth/scene_model.h"
#include "runtime/helper_thread.h"
#include "platform/huge_page_buffer.h"

namespace plumb::synth {

// A texture covers its quad exactly: texel (x, y) <-> (u, v) = ((x + 0.5), (y + 0.5)) / texels_per_metre.
struct SurfaceTexture {
  cv::Mat bgr;  // CV_8UC3, lighting baked in; empty until painted
  double texels_per_metre = 0;
};

class BakedTextures {
 public:
  // Keeps a reference to model (it must outlive this); reserves memory for every texture but
  // paints nothing yet. canvas_memory (optional, kept by the caller): memory that painting may
  // draw in before the blur, used when it holds the largest canvas. The renderer lends its colour
  // buffer, which is idle while faces are painted (before shading), so the first frame touches
  // ~3 MB less fresh memory (docs/EMBEDDED.md "First pose").
  explicit BakedTextures(const SceneModel& model, uint8_t* canvas_memory = nullptr, size_t canvas_memory_bytes = 0);

  // Paints and lights quad_index's texture unless that is done already.
  void prepare(int quad_index);
  // prepare() for each of quads[0..count). With a helper, the faces are shared between it and
  // the caller (each paints and lights its own, with its own scratch; memory is handed out in
  // list order first): the same texels as prepare() one by one.
  // Returns the number of faces it painted.
  int prepareAll(const int* quads, int count, runtime::HelperThread* helper);
  // The texture of a prepared quad.
  const SurfaceTexture& texture(int quad_index) const { return textures_[model_.quads[quad_index].texture]; }
  // The painting scratch in this object's block (both painters' gain buffers and canvases but a
  // lent one): a frame that paints procedural faces writes it.
  uint8_t* scratchData() const { return memory_.data(); }
  size_t scratchBytes() const { return memory_.data() ? scratch_bytes_ : 0; }

 private:
  bool painted(int quad_index) const { return taken_[model_.quads[quad_index].texture] != 0; }
  // Hands out the face's texture memory (list order: the same layout however it is painted).
  void take(int quad_index);
  // Paints and lights a taken face with painter k's scratch (k = 0: the caller, 1: the helper).
  void paintAndLight(int quad_index, int k);
  const SceneModel& model_;
  std::vector<SurfaceTexture> textures_;  // indexed like model.textures
  std::vector<uint8_t> taken_;            // indexed like model.textures: memory handed out
  // One block for every texture and the painting scratch, sized at construction: textures are
  // handed out from it as they are painted (huge pages: few page faults; see huge_page_buffer.h).
  HugePageBuffer memory_;
  size_t memory_used_ = 0;
  size_t scratch_bytes_ = 0;  // at the start of memory_
  PaintScratch scratch_[2];
  LightScratch light_scratch_[2];
  std::vector<int> share_[2];  // prepareAll: the faces each painter does
};

}  // namespace plumb::synth
