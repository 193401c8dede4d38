// Builds the synthetic room from boxes (see room_layout.h). Coordinates in metres, world z up;
// walls: x = 0 (west), x = W (east), y = 0 (south), y = D (north).
#include "drivers/synth/room_layout.h"

#include <algorithm>

#include <Eigen/Geometry>

#include "drivers/synth/light_baking.h"
#include "drivers/synth/surface_texture.h"
#include "drivers/synth/synth_random.h"

namespace plumb::synth {
namespace {

using Eigen::Vector3d;

class RoomBuilder {
 public:
  RoomBuilder(const RoomLayoutOptions& options, SceneModel& model)
      : options_(options),
        model_(model),
        rng_(mix64(options.seed ^ 0x526f6f6dULL)),
        texture_rng_(mix64(options.seed ^ 0x54657874ULL)) {}

  SplitMix64& rng() { return rng_; }

  // A colour around `base` (BGR), each channel jittered by +-spread.
  cv::Vec3f colour(const cv::Vec3f& base, double spread = 25) {
    cv::Vec3f c;
    for (int k = 0; k < 3; ++k) c[k] = static_cast<float>(std::clamp(base[k] + rng_.uniform(-spread, spread), 15.0, 245.0));
    return c;
  }

  // Adds a box; in textured mode its faces larger than a few centimetres get their own texture.
  void box(const Vector3d& min_world, const Vector3d& max_world, const cv::Vec3f& albedo, TextureStyle style,
           unsigned faces = kAllFaces, bool inward = false) {
    const int first = addBox(model_, min_world, max_world, albedo, faces, inward);
    if (!options_.textured) return;
    for (size_t q = first; q < model_.quads.size(); ++q) texture(static_cast<int>(q), style);
  }

  void texture(int quad_index, TextureStyle style) {
    SceneQuad& quad = model_.quads[quad_index];
    if (std::min(quad.length_u, quad.length_v) < 0.04) return;  // thin edges stay flat
    const bool big = style == TextureStyle::kWall || style == TextureStyle::kFloor;
    double tpm = big ? options_.wall_texels_per_metre : options_.object_texels_per_metre;
    if (style == TextureStyle::kCeiling) tpm = options_.wall_texels_per_metre / 3;
    quad.texture = static_cast<int>(model_.textures.size());
    model_.textures.push_back(
        planSurfaceTexture(quad.length_u, quad.length_v, tpm, style, quad.albedo_bgr, texture_rng_));
  }

  // A framed picture on a wall whose inward normal is `normal` (axis-aligned, horizontal).
  void picture(const Vector3d& centre_on_wall, const Vector3d& normal, double width, double height) {
    const Vector3d along = Vector3d::UnitZ().cross(normal);
    const Vector3d half = along.cwiseAbs() * width / 2 + Vector3d::UnitZ() * height / 2;
    const Vector3d frame_depth = normal * 0.03, canvas_depth = normal * 0.035;
    const Vector3d inset = along.cwiseAbs() * 0.04 + Vector3d::UnitZ() * 0.04;
    box((centre_on_wall - half).cwiseMin(centre_on_wall - half + frame_depth),
        (centre_on_wall + half).cwiseMax(centre_on_wall + half + frame_depth), colour({40, 50, 60}, 30),
        TextureStyle::kObject);
    const Vector3d c0 = centre_on_wall - half + inset, c1 = centre_on_wall + half - inset;
    box(c0.cwiseMin(c0 + canvas_depth), c1.cwiseMax(c1 + canvas_depth), colour({150, 150, 150}, 90),
        TextureStyle::kWall);
  }

 private:
  const RoomLayoutOptions& options_;
  SceneModel& model_;
  // Separate streams: both presets of one seed share the layout, only the textures differ.
  SplitMix64 rng_;
  SplitMix64 texture_rng_;
};

// A picture's random position along its wall and its size. The draws are separate statements: the
// order in which C++ evaluates function arguments is unspecified (GCC goes right to left on x86-64,
// left to right on aarch64), and a scene must be the same on every machine. Height, width, position
// is the order x86-64 builds always used, so existing scenes keep their bytes.
struct PictureDraws {
  double position, width, height;
};
struct Range {
  double lo, hi;
};
PictureDraws pictureDraws(SplitMix64& rng, Range position, Range width, Range height) {
  PictureDraws d;
  d.height = rng.uniform(height.lo, height.hi);
  d.width = rng.uniform(width.lo, width.hi);
  d.position = rng.uniform(position.lo, position.hi);
  return d;
}

void addShellAndTrim(RoomBuilder& b) {
  const double W = kRoomWidth, D = kRoomDepth, H = kRoomHeight;
  // Walls, floor, ceiling: distinct shades (the low-texture case relies on face contrast).
  const cv::Vec3f wall_base = b.colour({170, 180, 190}, 30);
  const float wall_gain[4] = {1.0f, 0.74f, 1.16f, 0.86f};  // adjacent walls differ clearly
  for (int w = 0; w < 4; ++w) {
    const unsigned face = 1u << w;  // kFaceMinX, kFaceMaxX, kFaceMinY, kFaceMaxY
    b.box(Vector3d::Zero(), Vector3d(W, D, H), b.colour(wall_base * wall_gain[w], 8), TextureStyle::kWall, face, true);
  }
  b.box(Vector3d::Zero(), Vector3d(W, D, H), b.colour({90, 110, 130}, 20), TextureStyle::kFloor, kFaceMinZ, true);
  b.box(Vector3d::Zero(), Vector3d(W, D, H), b.colour({225, 228, 230}, 8), TextureStyle::kCeiling, kFaceMaxZ, true);
  // Skirting boards: long, straight lines along every wall foot.
  const cv::Vec3f skirting = b.colour({235, 235, 235}, 15);
  const double t = 0.015, h = 0.08;
  b.box({0, 0, 0}, {W, t, h}, skirting, TextureStyle::kObject, kFaceMaxY | kFaceMaxZ);
  b.box({0, D - t, 0}, {W, D, h}, skirting, TextureStyle::kObject, kFaceMinY | kFaceMaxZ);
  b.box({0, 0, 0}, {t, D, h}, skirting, TextureStyle::kObject, kFaceMaxX | kFaceMaxZ);
  b.box({W - t, 0, 0}, {W, D, h}, skirting, TextureStyle::kObject, kFaceMinX | kFaceMaxZ);
}

void addNorthWall(RoomBuilder& b) {
  const double D = kRoomDepth;
  // Door with frame and handle.
  const double x0 = b.rng().uniform(0.9, 1.4), dw = 0.9, dh = 2.05;
  b.box({x0, D - 0.025, 0}, {x0 + dw, D, dh}, b.colour({110, 140, 170}), TextureStyle::kObject);
  const cv::Vec3f frame = b.colour({220, 220, 220}, 20);
  b.box({x0 - 0.07, D - 0.045, 0}, {x0, D, dh + 0.07}, frame, TextureStyle::kObject);
  b.box({x0 + dw, D - 0.045, 0}, {x0 + dw + 0.07, D, dh + 0.07}, frame, TextureStyle::kObject);
  b.box({x0, D - 0.045, dh}, {x0 + dw, D, dh + 0.07}, frame, TextureStyle::kObject);
  b.box({x0 + dw - 0.15, D - 0.08, 1.0}, {x0 + dw - 0.05, D - 0.025, 1.03}, b.colour({60, 60, 60}), TextureStyle::kObject);

  // Bookshelf: side panels, back, boards, books.
  const double xs = b.rng().uniform(4.0, 4.6), sw = 1.6, sd = 0.35, sh = 1.9, p = 0.02;
  const cv::Vec3f wood = b.colour({60, 100, 150}, 25);
  b.box({xs, D - 0.01, 0}, {xs + sw, D, sh}, b.colour(wood * 0.6f, 10), TextureStyle::kObject);
  b.box({xs, D - sd, 0}, {xs + p, D, sh}, wood, TextureStyle::kObject);
  b.box({xs + sw - p, D - sd, 0}, {xs + sw, D, sh}, wood, TextureStyle::kObject);
  const int boards = 5;
  for (int i = 0; i < boards; ++i) {
    const double z = i * (sh - p) / (boards - 1);
    b.box({xs + p, D - sd, z}, {xs + sw - p, D - 0.01, z + p}, wood, TextureStyle::kObject);
    if (i == boards - 1) break;
    for (double x = xs + p + b.rng().uniform(0.0, 0.1); x < xs + sw - p - 0.07;) {
      const double bw = b.rng().uniform(0.025, 0.06), bh = b.rng().uniform(0.18, 0.34), bd = b.rng().uniform(0.16, 0.26);
      b.box({x, D - 0.01 - bd, z + p}, {x + bw, D - 0.01, z + p + bh}, b.colour({120, 120, 120}, 100),
            TextureStyle::kObject);
      x += bw + (b.rng().uniform() < 0.15 ? b.rng().uniform(0.05, 0.2) : 0.003);
    }
  }
}

void addEastWall(RoomBuilder& b) {
  const double W = kRoomWidth;
  // Window: bright pane, frame and cross bars (protruding strips give strong lines).
  const double y0 = b.rng().uniform(1.8, 2.4), y1 = y0 + 1.5, z0 = 0.95, z1 = 2.15, f = 0.05;
  b.box({W - 0.01, y0, z0}, {W, y1, z1}, b.colour({235, 215, 190}, 10), TextureStyle::kCeiling);
  const cv::Vec3f frame = b.colour({240, 240, 240}, 10);
  b.box({W - 0.04, y0 - f, z0 - f}, {W, y0, z1 + f}, frame, TextureStyle::kObject);
  b.box({W - 0.04, y1, z0 - f}, {W, y1 + f, z1 + f}, frame, TextureStyle::kObject);
  b.box({W - 0.04, y0, z0 - f}, {W, y1, z0}, frame, TextureStyle::kObject);
  b.box({W - 0.04, y0, z1}, {W, y1, z1 + f}, frame, TextureStyle::kObject);
  b.box({W - 0.03, (y0 + y1) / 2 - 0.02, z0}, {W, (y0 + y1) / 2 + 0.02, z1}, frame, TextureStyle::kObject);
  b.box({W - 0.03, y0, (z0 + z1) / 2 - 0.02}, {W, y1, (z0 + z1) / 2 + 0.02}, frame, TextureStyle::kObject);
  // Sideboard under the window with three drawer fronts and handles.
  const double sy0 = y0 - 0.1, sy1 = y1 + 0.1, depth = 0.45, height = 0.8;
  b.box({W - depth, sy0, 0}, {W, sy1, height}, b.colour({80, 120, 160}), TextureStyle::kObject);
  const double dw = (sy1 - sy0) / 3;
  for (int i = 0; i < 3; ++i) {
    const double a = sy0 + i * dw + 0.02, c = sy0 + (i + 1) * dw - 0.02;
    b.box({W - depth - 0.012, a, 0.1}, {W - depth, c, height - 0.05}, b.colour({100, 140, 180}), TextureStyle::kObject);
    b.box({W - depth - 0.04, (a + c) / 2 - 0.08, height - 0.14}, {W - depth - 0.012, (a + c) / 2 + 0.08, height - 0.12},
          b.colour({50, 50, 50}), TextureStyle::kObject);
  }
}

void addSouthWall(RoomBuilder& b) {
  // Desk with legs and a monitor on a stand.
  const double x0 = b.rng().uniform(2.4, 3.0), x1 = x0 + 1.4, d = 0.7, top = 0.75;
  const cv::Vec3f desk = b.colour({70, 110, 140});
  b.box({x0, 0, top - 0.03}, {x1, d, top}, desk, TextureStyle::kObject);
  for (double x : {x0 + 0.03, x1 - 0.08})
    for (double y : {0.03, d - 0.08}) b.box({x, y, 0}, {x + 0.05, y + 0.05, top - 0.03}, desk * 0.7f, TextureStyle::kObject);
  const double mx = (x0 + x1) / 2;
  b.box({mx - 0.04, 0.12, top}, {mx + 0.04, 0.16, top + 0.15}, b.colour({40, 40, 40}, 10), TextureStyle::kObject);
  b.box({mx - 0.3, 0.1, top + 0.12}, {mx + 0.3, 0.14, top + 0.48}, b.colour({30, 30, 30}, 10), TextureStyle::kObject);
  b.box({mx - 0.27, 0.14, top + 0.15}, {mx + 0.27, 0.145, top + 0.45}, b.colour({120, 90, 60}, 40), TextureStyle::kWall);
  // Pictures beside it. Draws in the order height, width, position (see pictureDraws).
  const PictureDraws left = pictureDraws(b.rng(), {0.8, 1.6}, {0.5, 0.8}, {0.4, 0.6});
  b.picture({left.position, 0, 1.55}, Vector3d::UnitY(), left.width, left.height);
  const PictureDraws right = pictureDraws(b.rng(), {5.0, 6.2}, {0.5, 0.9}, {0.4, 0.7});
  b.picture({right.position, 0, 1.5}, Vector3d::UnitY(), right.width, right.height);
}

void addWestWall(RoomBuilder& b) {
  // Wardrobe with two doors and handles.
  const double y0 = b.rng().uniform(1.2, 1.8), y1 = y0 + 1.2, depth = 0.6, height = 2.0;
  b.box({0, y0, 0}, {depth, y1, height}, b.colour({150, 170, 190}), TextureStyle::kObject);
  const double ym = (y0 + y1) / 2;
  const cv::Vec3f door = b.colour({170, 190, 205});
  b.box({depth, y0 + 0.02, 0.05}, {depth + 0.015, ym - 0.005, height - 0.05}, door, TextureStyle::kObject);
  b.box({depth, ym + 0.005, 0.05}, {depth + 0.015, y1 - 0.02, height - 0.05}, door * 0.93f, TextureStyle::kObject);
  for (double y : {ym - 0.06, ym + 0.04})
    b.box({depth + 0.015, y, 0.9}, {depth + 0.04, y + 0.02, 1.2}, b.colour({50, 50, 50}), TextureStyle::kObject);
  const PictureDraws picture = pictureDraws(b.rng(), {3.8, 4.6}, {0.6, 1.0}, {0.5, 0.8});
  b.picture({0, picture.position, 1.5}, Vector3d::UnitX(), picture.width, picture.height);
}

void addCentre(RoomBuilder& b) {
  const double cx = kRoomWidth / 2 + b.rng().uniform(-0.1, 0.1), cy = kRoomDepth / 2 + b.rng().uniform(-0.1, 0.1);
  b.box({cx - 1.0, cy - 0.8, 0}, {cx + 1.0, cy + 0.8, 0.008}, b.colour({60, 60, 140}, 40), TextureStyle::kRug, kFaceMaxZ);
  // Table: top and four legs.
  const double top = 0.76;
  const cv::Vec3f wood = b.colour({50, 90, 130});
  b.box({cx - 0.5, cy - 0.3, top - 0.04}, {cx + 0.5, cy + 0.3, top}, wood, TextureStyle::kObject);
  for (double x : {cx - 0.46, cx + 0.41})
    for (double y : {cy - 0.26, cy + 0.21}) b.box({x, y, 0}, {x + 0.05, y + 0.05, top - 0.04}, wood * 0.8f, TextureStyle::kObject);
  // A box on the table and one under it.
  const double bx = cx + b.rng().uniform(-0.35, 0.05), by = cy + b.rng().uniform(-0.2, 0.0);
  b.box({bx, by, top}, {bx + 0.3, by + 0.22, top + 0.2}, b.colour({60, 140, 200}, 50), TextureStyle::kObject);
  b.box({cx + 0.05, cy - 0.2, 0.008}, {cx + 0.4, cy + 0.15, 0.4}, b.colour({90, 160, 120}, 50), TextureStyle::kObject);
}

}  // namespace

SceneModel buildRoom(const RoomLayoutOptions& options) {
  SceneModel model;
  model.room_min_world = Vector3d::Zero();
  model.room_max_world = Vector3d(kRoomWidth, kRoomDepth, kRoomHeight);
  model.lamp_world = Vector3d(kRoomWidth / 2, kRoomDepth / 2, kRoomHeight - 0.2);
  RoomBuilder builder(options, model);
  addShellAndTrim(builder);
  addNorthWall(builder);
  addEastWall(builder);
  addSouthWall(builder);
  addWestWall(builder);
  addCentre(builder);
  planLightMaps(model, options.lightmap_texels_per_metre);
  return model;
}

}  // namespace plumb::synth
