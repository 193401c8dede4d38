#pragma once
// The synthetic room: a 7.5 m x 6 m x 2.8 m interior (world frame z up, floor at z = 0) with
// skirting boards, a door with its frame, a bookshelf full of books, a window above a sideboard,
// a desk with a monitor, a wardrobe, framed pictures, a rug and a table with boxes in the middle.
// The seed jitters positions along the walls, colours, book sizes and textures; the middle stays
// clear enough for the camera path (camera_path.h), which circles the table at 1.2-2 m.
#include <cstdint>

#include "drivers/synth/scene_model.h"

namespace plumb::synth {

struct RoomLayoutOptions {
  bool textured = true;         // procedural textures on every face; false: flat shade per face
  uint64_t seed = 1;
  double wall_texels_per_metre = 150;    // walls, floor (a 5-7 mm texel: ~1 px at 1 m)
  double object_texels_per_metre = 220;  // furniture faces
  double lightmap_texels_per_metre = 16;  // untextured faces: a smooth baked light gradient
};

// Room interior bounds and the centre the camera circles.
constexpr double kRoomWidth = 7.5, kRoomDepth = 6.0, kRoomHeight = 2.8;

SceneModel buildRoom(const RoomLayoutOptions& options);

}  // namespace plumb::synth
