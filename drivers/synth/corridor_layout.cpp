// Builds the repeated-module corridor (see corridor_layout.h).
#include "drivers/synth/corridor_layout.h"

#include <algorithm>

#include "drivers/synth/light_baking.h"
#include "drivers/synth/surface_texture.h"
#include "drivers/synth/synth_random.h"

namespace plumb::synth {
namespace {

using Eigen::Vector3d;

class CorridorBuilder {
 public:
  CorridorBuilder(const CorridorLayoutOptions& options, SceneModel& model) : options_(options), model_(model) {}

  // A box whose textured faces draw from a generator seeded by `element` alone, so the same
  // element in every module gets the same texels.
  void box(const Vector3d& min_world, const Vector3d& max_world, const cv::Vec3f& albedo, TextureStyle style,
           uint64_t element, unsigned faces = kAllFaces) {
    const int first = addBox(model_, min_world, max_world, albedo, faces, false);
    SplitMix64 rng(mix64(options_.seed ^ (0x436f727269646f72ULL + element * 0x9e3779b97f4a7c15ULL)));
    for (std::size_t q = std::size_t(first); q < model_.quads.size(); ++q) {
      SceneQuad& quad = model_.quads[q];
      if (std::min(quad.length_u, quad.length_v) < 0.04) continue;  // thin edges stay flat
      const bool big = style == TextureStyle::kWall || style == TextureStyle::kFloor;
      double tpm = big ? options_.wall_texels_per_metre : options_.object_texels_per_metre;
      if (style == TextureStyle::kCeiling) tpm = options_.wall_texels_per_metre / 3;
      quad.texture = static_cast<int>(model_.textures.size());
      model_.textures.push_back(planSurfaceTexture(quad.length_u, quad.length_v, tpm, style, quad.albedo_bgr, rng));
    }
  }

 private:
  const CorridorLayoutOptions& options_;
  SceneModel& model_;
};

// Colours of the template, drawn once.
struct ModuleColours {
  cv::Vec3f wall_north, wall_south, floor, ceiling, door, frame, skirting, picture_frame, canvas, light, sign;
};

ModuleColours drawColours(uint64_t seed) {
  SplitMix64 rng(mix64(seed ^ 0x436f6c6f757273ULL));
  auto colour = [&rng](const cv::Vec3f& base, double spread) {
    cv::Vec3f c;
    for (int k = 0; k < 3; ++k) c[k] = static_cast<float>(std::clamp(base[k] + rng.uniform(-spread, spread), 15.0, 245.0));
    return c;
  };
  ModuleColours c;
  c.wall_north = colour({170, 180, 190}, 25);
  c.wall_south = colour(c.wall_north * 0.8f, 8);
  c.floor = colour({90, 110, 130}, 20);
  c.ceiling = colour({225, 228, 230}, 8);
  c.door = colour({110, 140, 170}, 25);
  c.frame = colour({220, 220, 220}, 20);
  c.skirting = colour({235, 235, 235}, 15);
  c.picture_frame = colour({40, 50, 60}, 30);
  c.canvas = colour({150, 150, 150}, 90);
  c.light = colour({240, 240, 240}, 5);
  c.sign = colour({200, 200, 200}, 40);
  return c;
}

// Element ids: the same for every module (the copies), except the sign.
enum Element : uint64_t {
  kNorthWall = 1, kSouthWall, kFloor, kCeiling, kDoor, kDoorFrame, kHandle, kSkirting, kPictureFrame, kCanvas,
  kLight, kEndWalls, kSignBase = 1000,
};

void addModule(CorridorBuilder& b, const ModuleColours& c, int module) {
  const double W = kCorridorWidth, H = kCorridorHeight, P = kCorridorModuleLength;
  const double x0 = module * P, x1 = x0 + P;
  // Shell panels: a face of a thin box just outside the corridor, facing in.
  b.box({x0, W, 0}, {x1, W + 0.1, H}, c.wall_north, TextureStyle::kWall, kNorthWall, kFaceMinY);
  b.box({x0, -0.1, 0}, {x1, 0, H}, c.wall_south, TextureStyle::kWall, kSouthWall, kFaceMaxY);
  b.box({x0, 0, -0.1}, {x1, W, 0}, c.floor, TextureStyle::kFloor, kFloor, kFaceMaxZ);
  b.box({x0, 0, H}, {x1, W, H + 0.1}, c.ceiling, TextureStyle::kCeiling, kCeiling, kFaceMinZ);
  // Skirting boards.
  const double t = 0.015, h = 0.08;
  b.box({x0, W - t, 0}, {x1, W, h}, c.skirting, TextureStyle::kObject, kSkirting, kFaceMinY | kFaceMaxZ);
  b.box({x0, 0, 0}, {x1, t, h}, c.skirting, TextureStyle::kObject, kSkirting, kFaceMaxY | kFaceMaxZ);
  // Door with frame and handle on the north wall.
  const double dx = x0 + 0.7, dw = 0.9, dh = 2.05;
  b.box({dx, W - 0.025, 0}, {dx + dw, W, dh}, c.door, TextureStyle::kObject, kDoor);
  b.box({dx - 0.07, W - 0.045, 0}, {dx, W, dh + 0.07}, c.frame, TextureStyle::kObject, kDoorFrame);
  b.box({dx + dw, W - 0.045, 0}, {dx + dw + 0.07, W, dh + 0.07}, c.frame, TextureStyle::kObject, kDoorFrame);
  b.box({dx, W - 0.045, dh}, {dx + dw, W, dh + 0.07}, c.frame, TextureStyle::kObject, kDoorFrame);
  b.box({dx + dw - 0.15, W - 0.08, 1.0}, {dx + dw - 0.05, W - 0.025, 1.03}, cv::Vec3f(60, 60, 60),
        TextureStyle::kObject, kHandle);
  // The one unique thing: a sign beside the door, its pattern drawn from the module number.
  const double sx = dx + dw + 0.25;
  b.box({sx, W - 0.012, 1.45}, {sx + 0.30, W, 1.65}, c.sign, TextureStyle::kObject, kSignBase + uint64_t(module));
  // A framed picture on the south wall, facing the door.
  const double px = x0 + 1.0, pw = 1.0, pz0 = 1.1, pz1 = 1.8;
  b.box({px, 0, pz0}, {px + pw, 0.03, pz1}, c.picture_frame, TextureStyle::kObject, kPictureFrame);
  b.box({px + 0.05, 0.03, pz0 + 0.05}, {px + pw - 0.05, 0.035, pz1 - 0.05}, c.canvas, TextureStyle::kWall, kCanvas);
  // Ceiling light.
  b.box({x0 + P / 2 - 0.6, W / 2 - 0.15, H - 0.04}, {x0 + P / 2 + 0.6, W / 2 + 0.15, H}, c.light,
        TextureStyle::kCeiling, kLight);
}

}  // namespace

SceneModel buildCorridor(const CorridorLayoutOptions& options) {
  SceneModel model;
  model.room_min_world = Vector3d::Zero();
  model.room_max_world = Vector3d(kCorridorLength, kCorridorWidth, kCorridorHeight);
  model.lamp_world = Vector3d(kCorridorLength / 2, kCorridorWidth / 2, kCorridorHeight - 0.2);
  model.lamp_strength = 0.0f;  // a lamp gradient would make the modules differ
  CorridorBuilder builder(options, model);
  const ModuleColours colours = drawColours(options.seed);
  for (int m = 0; m < kCorridorModules; ++m) addModule(builder, colours, m);
  // End walls (unique).
  builder.box({-0.1, 0, 0}, {0, kCorridorWidth, kCorridorHeight}, colours.wall_south, TextureStyle::kWall, kEndWalls,
              kFaceMaxX);
  builder.box({kCorridorLength, 0, 0}, {kCorridorLength + 0.1, kCorridorWidth, kCorridorHeight}, colours.wall_north,
              TextureStyle::kWall, kEndWalls + 500, kFaceMinX);
  planLightMaps(model, options.lightmap_texels_per_metre);
  return model;
}

}  // namespace plumb::synth
