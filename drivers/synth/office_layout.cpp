// Builds the open-plan office (see office_layout.h).
#include "drivers/synth/office_layout.h"

#include <algorithm>

#include <Eigen/Geometry>

#include "drivers/synth/light_baking.h"
#include "drivers/synth/surface_texture.h"
#include "drivers/synth/synth_random.h"

namespace plumb::synth {
namespace {

using Eigen::Vector3d;

// Element ids name what a texture is drawn for: copies of one piece of furniture share the id,
// hence the texels. Unique things get ids of their own.
enum Element : uint64_t {
  kCarpet = 1, kDeskTop, kScreen, kKeyboard, kWhiteboard, kPosterBase = 100,
};

class OfficeBuilder {
 public:
  OfficeBuilder(const OfficeLayoutOptions& options, SceneModel& model)
      : options_(options), model_(model), colour_rng_(mix64(options.seed ^ 0x4f6666696365ULL)) {}

  // A colour around `base` (BGR), each channel jittered by +-spread (drawn once per call: call it
  // once per kind of furniture, not per copy, so copies share it).
  cv::Vec3f colour(const cv::Vec3f& base, double spread = 20) {
    cv::Vec3f c;
    for (int k = 0; k < 3; ++k)
      c[k] = static_cast<float>(std::clamp(base[k] + colour_rng_.uniform(-spread, spread), 15.0, 245.0));
    return c;
  }

  // A flat box (light map only).
  void flat(const Vector3d& min_world, const Vector3d& max_world, const cv::Vec3f& albedo,
            unsigned faces = kAllFaces, bool inward = false) {
    addBox(model_, min_world, max_world, albedo, faces, inward);
  }

  // A box whose faces (larger than 4 cm) are textured from a generator seeded by `element` alone.
  void textured(const Vector3d& min_world, const Vector3d& max_world, const cv::Vec3f& albedo, TextureStyle style,
                uint64_t element, unsigned faces = kAllFaces, bool inward = false) {
    const int first = addBox(model_, min_world, max_world, albedo, faces, inward);
    SplitMix64 rng(mix64(options_.seed ^ (0x4f66546578ULL + element * 0x9e3779b97f4a7c15ULL)));
    for (std::size_t q = std::size_t(first); q < model_.quads.size(); ++q) {
      SceneQuad& quad = model_.quads[q];
      if (std::min(quad.length_u, quad.length_v) < 0.04) continue;
      const bool big = style == TextureStyle::kWall || style == TextureStyle::kFloor;
      const double tpm = big ? options_.wall_texels_per_metre : options_.object_texels_per_metre;
      quad.texture = static_cast<int>(model_.textures.size());
      model_.textures.push_back(planSurfaceTexture(quad.length_u, quad.length_v, tpm, style, quad.albedo_bgr, rng));
    }
  }

 private:
  const OfficeLayoutOptions& options_;
  SceneModel& model_;
  SplitMix64 colour_rng_;
};

struct OfficeColours {
  cv::Vec3f walls[4], ceiling, carpet, skirting, desk, desk_leg, monitor, chair_seat, chair_frame, window_pane,
      window_frame, shelf, cabinet, drawer, handle, door, door_frame, board_frame, whiteboard, light_panel,
      meeting_table;
  cv::Vec3f books[12];
};

OfficeColours drawColours(OfficeBuilder& b) {
  OfficeColours c;
  const cv::Vec3f wall = b.colour({200, 205, 210}, 15);
  const float gain[4] = {1.0f, 0.8f, 1.1f, 0.9f};  // adjacent walls differ (light, not paint)
  for (int w = 0; w < 4; ++w) c.walls[w] = wall * gain[w];
  c.ceiling = b.colour({230, 232, 235}, 5);
  c.carpet = b.colour({110, 100, 90}, 25);
  c.skirting = b.colour({70, 70, 70}, 15);
  c.desk = b.colour({120, 160, 190}, 25);
  c.desk_leg = b.colour({60, 60, 60}, 15);
  c.monitor = b.colour({30, 30, 30}, 8);
  c.chair_seat = b.colour({60, 40, 140}, 30);
  c.chair_frame = b.colour({40, 40, 40}, 10);
  c.window_pane = b.colour({235, 220, 200}, 10);
  c.window_frame = b.colour({245, 245, 245}, 8);
  c.shelf = b.colour({90, 130, 170}, 25);
  c.cabinet = b.colour({160, 165, 170}, 20);
  c.drawer = c.cabinet * 1.08f;
  c.handle = b.colour({40, 40, 40}, 10);
  c.door = b.colour({100, 130, 160}, 25);
  c.door_frame = b.colour({220, 220, 220}, 15);
  c.board_frame = b.colour({150, 150, 150}, 20);
  c.whiteboard = b.colour({240, 240, 240}, 5);
  c.light_panel = b.colour({250, 250, 250}, 3);
  c.meeting_table = b.colour({70, 110, 150}, 25);
  for (cv::Vec3f& book : c.books) book = b.colour({120, 120, 120}, 100);
  return c;
}

void addShell(OfficeBuilder& b, const OfficeColours& c) {
  const double W = kOfficeWidth, D = kOfficeDepth, H = kOfficeHeight;
  for (int w = 0; w < 4; ++w) b.flat(Vector3d::Zero(), Vector3d(W, D, H), c.walls[w], 1u << w, true);
  b.textured(Vector3d::Zero(), Vector3d(W, D, H), c.carpet, TextureStyle::kFloor, kCarpet, kFaceMinZ, true);
  b.flat(Vector3d::Zero(), Vector3d(W, D, H), c.ceiling, kFaceMaxZ, true);
  const double t = 0.015, h = 0.1;
  b.flat({0, 0, 0}, {W, t, h}, c.skirting, kFaceMaxY | kFaceMaxZ);
  b.flat({0, D - t, 0}, {W, D, h}, c.skirting, kFaceMinY | kFaceMaxZ);
  b.flat({0, 0, 0}, {t, D, h}, c.skirting, kFaceMaxX | kFaceMaxZ);
  b.flat({W - t, 0, 0}, {W, D, h}, c.skirting, kFaceMinX | kFaceMaxZ);
  // Ceiling light panels: a 3 x 3 grid of 1.2 m x 0.6 m recessed rectangles.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double x = 1.5 + 3.0 * i - 0.6, y = 1.2 + 2.3 * j - 0.3;
      b.flat({x, y, H - 0.01}, {x + 1.2, y + 0.6, H}, c.light_panel, kFaceMinZ);
    }
}

// A chair centred at (x, y), its back on the +y side when back_towards_plus_y, else on the -y side.
void addChair(OfficeBuilder& b, const OfficeColours& c, double x, double y, bool back_towards_plus_y) {
  const double s = 0.23, seat_z = 0.46;
  b.flat({x - 0.03, y - 0.03, 0.08}, {x + 0.03, y + 0.03, seat_z - 0.03}, c.chair_frame);  // post
  b.flat({x - 0.28, y - 0.03, 0.04}, {x + 0.28, y + 0.03, 0.08}, c.chair_frame);           // base
  b.flat({x - 0.03, y - 0.28, 0.04}, {x + 0.03, y + 0.28, 0.08}, c.chair_frame);
  b.flat({x - s, y - s, seat_z - 0.03}, {x + s, y + s, seat_z + 0.04}, c.chair_seat);  // seat
  const double by0 = back_towards_plus_y ? y + s - 0.05 : y - s, by1 = by0 + 0.05;
  b.flat({x - s, by0, seat_z + 0.12}, {x + s, by1, seat_z + 0.52}, c.chair_seat);  // back
  b.flat({x - 0.02, by0, seat_z + 0.04}, {x + 0.02, by1, seat_z + 0.12}, c.chair_frame);
}

void addSouthWall(OfficeBuilder& b, const OfficeColours& c) {
  const double d = 0.75, top = 0.74;
  for (int k = 0; k < kOfficeWorkstations; ++k) {
    const double x0 = 0.85 + k * kOfficeWorkstationPitch, x1 = x0 + 1.4, mx = (x0 + x1) / 2;
    // Desk: top, four legs, a modesty panel.
    b.textured({x0, 0, top - 0.03}, {x1, d, top}, c.desk, TextureStyle::kObject, kDeskTop);
    for (double x : {x0 + 0.03, x1 - 0.08})
      for (double y : {0.03, d - 0.08}) b.flat({x, y, 0}, {x + 0.05, y + 0.05, top - 0.03}, c.desk_leg);
    b.flat({x0 + 0.1, 0.05, 0.3}, {x1 - 0.1, 0.07, top - 0.03}, c.desk * 0.8f);
    // Monitor on a stand, keyboard.
    b.flat({mx - 0.04, 0.15, top}, {mx + 0.04, 0.19, top + 0.15}, c.monitor);
    b.flat({mx - 0.12, 0.1, top}, {mx + 0.12, 0.25, top + 0.01}, c.monitor);
    b.flat({mx - 0.32, 0.12, top + 0.12}, {mx + 0.32, 0.16, top + 0.5}, c.monitor);
    b.textured({mx - 0.29, 0.16, top + 0.15}, {mx + 0.29, 0.165, top + 0.47}, c.monitor * 3.0f, TextureStyle::kWall,
               kScreen, kFaceMaxY);
    b.textured({mx - 0.22, 0.3, top}, {mx + 0.22, 0.45, top + 0.02}, c.monitor * 2.0f, TextureStyle::kObject,
               kKeyboard, kFaceMaxZ | kFaceMaxY);
    addChair(b, c, mx, d + 0.35, true);
    // The window above it: pane, frame, a vertical and a horizontal mullion.
    const double z0 = 1.05, z1 = 2.35, f = 0.06, w0 = mx - 0.65, w1 = mx + 0.65;
    b.flat({w0, 0, z0}, {w1, 0.01, z1}, c.window_pane, kFaceMaxY);
    b.flat({w0 - f, 0, z0 - f}, {w0, 0.05, z1 + f}, c.window_frame);
    b.flat({w1, 0, z0 - f}, {w1 + f, 0.05, z1 + f}, c.window_frame);
    b.flat({w0, 0, z0 - f}, {w1, 0.05, z0}, c.window_frame);
    b.flat({w0, 0, z1}, {w1, 0.05, z1 + f}, c.window_frame);
    b.flat({mx - 0.02, 0, z0}, {mx + 0.02, 0.04, z1}, c.window_frame);
    b.flat({w0, 0, 1.75}, {w1, 0.04, 1.79}, c.window_frame);
  }
}

void addNorthWall(OfficeBuilder& b, const OfficeColours& c) {
  const double D = kOfficeDepth, sw = 1.6, sd = 0.35, sh = 1.9, p = 0.02;
  for (double xs : {0.8, 2.7, 4.6}) {
    b.flat({xs, D - 0.01, 0}, {xs + sw, D, sh}, c.shelf * 0.6f);
    b.flat({xs, D - sd, 0}, {xs + p, D, sh}, c.shelf);
    b.flat({xs + sw - p, D - sd, 0}, {xs + sw, D, sh}, c.shelf);
    // Books: the same sizes and colours in every copy (one generator per shelf, same seed).
    SplitMix64 books(0x426f6f6b73ULL);
    const int boards = 5;
    for (int i = 0; i < boards; ++i) {
      const double z = i * (sh - p) / (boards - 1);
      b.flat({xs + p, D - sd, z}, {xs + sw - p, D - 0.01, z + p}, c.shelf);
      if (i == boards - 1) break;
      for (double x = xs + p + books.uniform(0.0, 0.1); x < xs + sw - p - 0.07;) {
        const double bw = books.uniform(0.025, 0.06), bh = books.uniform(0.18, 0.34), bd = books.uniform(0.16, 0.26);
        const cv::Vec3f& colour = c.books[books.uniformInt(0, 11)];
        b.flat({x, D - 0.01 - bd, z + p}, {x + bw, D - 0.01, z + p + bh}, colour);
        x += bw + (books.uniform() < 0.15 ? books.uniform(0.05, 0.2) : 0.003);
      }
    }
  }
  // Door with frame and handle.
  const double x0 = 7.1, dw = 0.95, dh = 2.1;
  b.flat({x0, D - 0.025, 0}, {x0 + dw, D, dh}, c.door);
  b.flat({x0 - 0.07, D - 0.045, 0}, {x0, D, dh + 0.07}, c.door_frame);
  b.flat({x0 + dw, D - 0.045, 0}, {x0 + dw + 0.07, D, dh + 0.07}, c.door_frame);
  b.flat({x0, D - 0.045, dh}, {x0 + dw, D, dh + 0.07}, c.door_frame);
  b.flat({x0 + dw - 0.15, D - 0.08, 1.0}, {x0 + dw - 0.05, D - 0.025, 1.03}, c.handle);
}

// A framed poster centred on a wall point, `normal` the wall's inward normal (horizontal, axis).
void addPoster(OfficeBuilder& b, const OfficeColours& c, const Vector3d& centre, const Vector3d& normal, double width,
               double height, uint64_t element) {
  const Vector3d along = Vector3d::UnitZ().cross(normal).cwiseAbs();
  const Vector3d half = along * width / 2 + Vector3d::UnitZ() * height / 2;
  const Vector3d lo = centre - half, hi = centre + half;
  b.flat(lo.cwiseMin(lo + normal * 0.02), hi.cwiseMax(hi + normal * 0.02), c.board_frame);
  const Vector3d inset = along * 0.03 + Vector3d::UnitZ() * 0.03;
  const Vector3d p0 = lo + inset, p1 = hi - inset;
  b.textured(p0.cwiseMin(p0 + normal * 0.025), p1.cwiseMax(p1 + normal * 0.025), cv::Vec3f(150, 150, 150),
             TextureStyle::kWall, element);
}

void addWestWall(OfficeBuilder& b, const OfficeColours& c) {
  const double depth = 0.6, width = 0.5, height = 1.3;
  for (double y0 : {1.9, 2.45, 3.0}) {
    b.flat({0, y0, 0}, {depth, y0 + width, height}, c.cabinet);
    for (int k = 0; k < 3; ++k) {
      const double z0 = 0.06 + k * 0.41, z1 = z0 + 0.37;
      b.flat({depth, y0 + 0.02, z0}, {depth + 0.012, y0 + width - 0.02, z1}, c.drawer);
      b.flat({depth + 0.012, y0 + width / 2 - 0.08, z1 - 0.08}, {depth + 0.035, y0 + width / 2 + 0.08, z1 - 0.06},
             c.handle);
    }
  }
  addPoster(b, c, {0, 5.2, 1.6}, Vector3d::UnitX(), 0.9, 1.2, kPosterBase + 0);
}

void addEastWall(OfficeBuilder& b, const OfficeColours& c) {
  const double W = kOfficeWidth;
  // Whiteboard with an aluminium frame and a tray.
  const double y0 = 2.6, y1 = 4.4, z0 = 0.95, z1 = 2.05, f = 0.03;
  b.textured({W - 0.012, y0, z0}, {W, y1, z1}, c.whiteboard, TextureStyle::kObject, kWhiteboard, kFaceMinX);
  b.flat({W - 0.03, y0 - f, z0 - f}, {W, y0, z1 + f}, c.board_frame);
  b.flat({W - 0.03, y1, z0 - f}, {W, y1 + f, z1 + f}, c.board_frame);
  b.flat({W - 0.03, y0, z0 - f}, {W, y1, z0}, c.board_frame);
  b.flat({W - 0.03, y0, z1}, {W, y1, z1 + f}, c.board_frame);
  b.flat({W - 0.08, y0 + 0.2, z0 - 0.06}, {W - 0.03, y1 - 0.2, z0 - 0.03}, c.board_frame);
  addPoster(b, c, {W, 1.3, 1.55}, -Vector3d::UnitX(), 0.7, 1.0, kPosterBase + 1);
  addPoster(b, c, {W, 5.7, 1.55}, -Vector3d::UnitX(), 0.7, 1.0, kPosterBase + 2);
}

void addMeetingTable(OfficeBuilder& b, const OfficeColours& c) {
  const double cx = 4.5, cy = 3.6, hx = 1.2, hy = 0.5, top = 0.74;
  b.flat({cx - hx, cy - hy, top - 0.04}, {cx + hx, cy + hy, top}, c.meeting_table);
  for (double x : {cx - hx + 0.1, cx + hx - 0.16})
    for (double y : {cy - hy + 0.1, cy + hy - 0.16}) b.flat({x, y, 0}, {x + 0.06, y + 0.06, top - 0.04}, c.desk_leg);
  for (double x : {cx - 0.8, cx, cx + 0.8}) {
    addChair(b, c, x, cy - hy - 0.3, false);
    addChair(b, c, x, cy + hy + 0.3, true);
  }
}

}  // namespace

SceneModel buildOffice(const OfficeLayoutOptions& options) {
  SceneModel model;
  model.room_min_world = Vector3d::Zero();
  model.room_max_world = Vector3d(kOfficeWidth, kOfficeDepth, kOfficeHeight);
  model.lamp_world = Vector3d(kOfficeWidth / 2, kOfficeDepth / 2, kOfficeHeight - 0.2);
  OfficeBuilder builder(options, model);
  const OfficeColours colours = drawColours(builder);
  addShell(builder, colours);
  addSouthWall(builder, colours);
  addNorthWall(builder, colours);
  addWestWall(builder, colours);
  addEastWall(builder, colours);
  addMeetingTable(builder, colours);
  planLightMaps(model, options.lightmap_texels_per_metre);
  return model;
}

}  // namespace plumb::synth
