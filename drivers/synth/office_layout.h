#pragma once
// The "office" scenes (presets office_loop, office_pass): an open-plan office of 9 m (x) x 7 m (y)
// x 2.8 m (z), world frame z up, floor at z = 0, walls x = 0 (west), x = 9 (east), y = 0 (south),
// y = 7 (north). Built to reproduce what a rendered office dataset (ICL-NUIM-like) shows a
// point+line SLAM system: plain walls and many long straight edges, with REPEATED furniture:
//
//   south wall   five identical workstations (desk, legs, monitor, keyboard, chair) under five
//                identical windows (pane, frame, one vertical and one horizontal mullion)
//   north wall   three identical bookshelves (boards and the same books), a door with its frame
//   west wall    three identical filing cabinets (drawer fronts, handles), a poster
//   east wall    a framed whiteboard, two posters
//   middle       a meeting table with six identical chairs
//   ceiling      a 3 x 3 grid of light panels; skirting boards along every wall
//
// Walls, ceiling and most furniture faces are flat shades (a smooth baked light gradient only);
// posters, the whiteboard's marks, the carpet tiles, desk tops and monitor screens are textured.
// Copies of one piece of furniture are identical down to the texels (their textures are drawn
// from a generator seeded by the element, as the corridor's modules are), so only their place in
// the room tells them apart. The seed changes colours, textures and the posters, not positions:
// the camera paths (office_path.h, camera_path.h) rely on the fixed layout.
#include <cstdint>

#include "drivers/synth/scene_model.h"

namespace plumb::synth {

constexpr double kOfficeWidth = 9.0, kOfficeDepth = 7.0, kOfficeHeight = 2.8;
constexpr int kOfficeWorkstations = 5;
constexpr double kOfficeWorkstationPitch = 1.75;  // x distance between copies along the south wall

struct OfficeLayoutOptions {
  uint64_t seed = 1;
  double wall_texels_per_metre = 150;
  double object_texels_per_metre = 220;
  double lightmap_texels_per_metre = 16;
};

SceneModel buildOffice(const OfficeLayoutOptions& options);

}  // namespace plumb::synth
