// Synthetic textures painted on first use: the fast paths (separable light baking, SIMD texel
// multiply) equal their plain formulas bit for bit, and a frame does not depend on which frames
// were rendered before it (the order in which faces got painted).
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <numeric>
#include <vector>

#include <opencv2/core.hpp>

#include "drivers/synth/baked_textures.h"
#include "drivers/synth/corridor_layout.h"
#include "drivers/synth/light_baking.h"
#include "drivers/synth/room_layout.h"
#include "drivers/synth/synth_random.h"
#include "drivers/synth/synthetic_scene.h"
#include "drivers/synth/texel_gain.h"
#include "runtime/helper_thread.h"

namespace plumb {
namespace {

bool sameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::countNonZero(cv::Mat(a != b).reshape(1)) == 0;
}

// Random texels the size of the quad's texture (the light is multiplied into whatever is painted).
cv::Mat randomTexture(const synth::TextureRecipe& recipe, uint64_t seed) {
  cv::Mat bgr(recipe.rows, recipe.cols, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(bgr, cv::RNG::UNIFORM, 0, 256);
  return bgr;
}

// Every quad of the model: the separable bake equals the per-texel formula to the byte.
void expectBakeMatchesOracle(const synth::SceneModel& model) {
  ASSERT_FALSE(model.quads.empty());
  int lit_by_lamp = 0;
  synth::LightScratch scratch;  // grows from empty, quad after quad
  for (size_t q = 0; q < model.quads.size(); ++q) {
    const synth::SceneQuad& quad = model.quads[q];
    ASSERT_GE(quad.texture, 0);
    const synth::TextureRecipe& recipe = model.textures[quad.texture];
    cv::Mat fast = randomTexture(recipe, q + 1), oracle = fast.clone();
    synth::bakeLighting(model, quad, recipe.texels_per_metre, fast, scratch);
    synth::bakeLightingPerTexel(model, quad, recipe.texels_per_metre, oracle);
    ASSERT_TRUE(sameBytes(fast, oracle)) << "quad " << q;
    if (quad.normal_world.dot(model.lamp_world - quad.origin_world) > 0) ++lit_by_lamp;
  }
  // Most faces face the lamp: the per-texel lamp term (not only the constant sun) is compared.
  if (model.lamp_strength > 0) {
    EXPECT_GT(lit_by_lamp, static_cast<int>(model.quads.size()) / 4);
  }
}

TEST(SynthTextures, SeparableLightBakingEqualsThePerTexelFormula) {
  synth::RoomLayoutOptions room;
  SCOPED_TRACE("textured room");
  expectBakeMatchesOracle(synth::buildRoom(room));
  room.textured = false;
  SCOPED_TRACE("plain room");
  expectBakeMatchesOracle(synth::buildRoom(room));
  SCOPED_TRACE("corridor");
  expectBakeMatchesOracle(synth::buildCorridor(synth::CorridorLayoutOptions{}));
}

TEST(SynthTextures, TiltedQuadsTakeThePerTexelPath) {
  synth::SceneModel model = synth::buildRoom(synth::RoomLayoutOptions{});
  synth::SceneQuad quad = model.quads[0];
  const Eigen::AngleAxisd tilt(0.3, Eigen::Vector3d(1, 2, 3).normalized());
  quad.axis_u_world = tilt * quad.axis_u_world;
  quad.axis_v_world = tilt * quad.axis_v_world;
  quad.normal_world = tilt * quad.normal_world;
  const synth::TextureRecipe& recipe = model.textures[quad.texture];
  cv::Mat fast = randomTexture(recipe, 5), oracle = fast.clone();
  synth::LightScratch scratch;
  synth::bakeLighting(model, quad, recipe.texels_per_metre, fast, scratch);
  synth::bakeLightingPerTexel(model, quad, recipe.texels_per_metre, oracle);
  EXPECT_TRUE(sameBytes(fast, oracle));
}

TEST(SynthTextures, SimdTexelMultiplyEqualsSaturateCast) {
  synth::SplitMix64 rng(11);
  for (int count : {1, 15, 16, 17, 47, 640, 1125}) {
    SCOPED_TRACE(count);
    std::vector<cv::Vec3b> texels(count), expected(count);
    std::vector<float> gain(count);
    for (int i = 0; i < count; ++i) {
      for (int k = 0; k < 3; ++k) texels[i][k] = static_cast<uchar>(rng.uniformInt(0, 255));
      // Gains around 1 (shading), up to 2 (saturating) and exact halves (rounding ties to even).
      const int kind = i % 3;
      gain[i] = kind == 0 ? static_cast<float>(rng.uniform(0.5, 1.5))
                : kind == 1 ? static_cast<float>(rng.uniform(0.0, 2.0))
                            : 0.5f + 1.0f * static_cast<float>(rng.uniformInt(0, 2));
    }
    for (int i = 0; i < count; ++i)
      for (int k = 0; k < 3; ++k) expected[i][k] = cv::saturate_cast<uchar>(texels[i][k] * gain[i]);
    synth::multiplyTexels(texels.data(), gain.data(), count);
    for (int i = 0; i < count; ++i) ASSERT_EQ(texels[i], expected[i]) << "texel " << i << " gain " << gain[i];
  }
}

// The renderer paints a frame's faces with prepareAll (shared between the caller and a helper
// thread, each with its own scratch; the caller's canvas lent by the renderer, its colour
// buffer): the texels of prepare(), face by face, on one thread with the textures' own canvas.
TEST(SynthTextures, PaintingWithAHelperThreadAndALentCanvasGivesTheSameTexels) {
  for (const synth::SceneModel& model :
       {synth::buildRoom(synth::RoomLayoutOptions{}), synth::buildCorridor(synth::CorridorLayoutOptions{})}) {
    std::vector<int> quads(model.quads.size());
    std::iota(quads.begin(), quads.end(), 0);
    synth::BakedTextures one_by_one(model);
    for (int q : quads) one_by_one.prepare(q);
    std::vector<uint8_t> lent(std::size_t(16) << 20);
    synth::BakedTextures overlapped(model, lent.data(), lent.size());
    runtime::HelperThread helper;
    overlapped.prepareAll(quads.data(), static_cast<int>(quads.size()), &helper);
    for (int q : quads) ASSERT_TRUE(sameBytes(one_by_one.texture(q).bgr, overlapped.texture(q).bgr)) << "quad " << q;
    // Some pairs of faces are large enough to be overlapped (>= 64k texels), or this tests nothing.
    int large = 0;
    for (const synth::TextureRecipe& r : model.textures) large += long(r.rows) * r.cols >= 32 * 1024;
    EXPECT_GE(large, 2);
  }
}

TEST(SynthTextures, AFrameDoesNotDependOnTheFramesRenderedBeforeIt) {
  // Faces are painted when a frame first shows them: a scene that rendered far-away frames first
  // has painted other faces, in another order, and must still give the same bytes.
  for (const char* preset : {"textured", "repeated"}) {
    SCOPED_TRACE(preset);
    SynthOptions options;
    options.preset = preset;
    options.frames = 400;
    options.pixel_noise_sigma = 1.5;
    std::unique_ptr<SyntheticScene> fresh, travelled;
    ASSERT_TRUE(SyntheticScene::create(options, &fresh).ok());
    ASSERT_TRUE(SyntheticScene::create(options, &travelled).ok());
    RgbdImage first, again, elsewhere;
    ASSERT_TRUE(fresh->render(0, first).ok());
    ASSERT_TRUE(travelled->render(390, elsewhere).ok());
    ASSERT_TRUE(travelled->render(200, elsewhere).ok());
    ASSERT_TRUE(travelled->render(0, again).ok());
    EXPECT_FALSE(sameBytes(first.bgr, elsewhere.bgr));
    EXPECT_TRUE(sameBytes(first.bgr, again.bgr));
    EXPECT_TRUE(sameBytes(first.depth_raw, again.depth_raw));
  }
}

}  // namespace
}  // namespace plumb
