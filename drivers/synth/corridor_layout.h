#pragma once
// The "repeated" scene: a long straight corridor built from identical modules, for testing that a
// loop detector does not close a loop that is not there. World frame z up, metres; the corridor
// runs along +x from x = 0 to kCorridorModules * kCorridorModuleLength, y in [0, kCorridorWidth].
//
// Every module (kCorridorModuleLength long) is a copy of one template: the same wall, floor and
// ceiling textures (each regenerated from the same seed, not shared, so lighting bakes per face),
// a door with its frame on the north wall (y = width), a framed picture on the south wall (y = 0),
// skirting boards and a ceiling light. No lamp gradient (lamp_strength 0): the copies look the
// same from the same relative viewpoint, up to pixel noise. The only thing that tells modules
// apart is a small sign beside each door (0.30 m x 0.20 m) with its own random pattern, as room
// numbers tell real office doors apart. The two end walls are unique, but the camera path
// (corridor_path.h) keeps them out of sight most of the time.
#include <cstdint>

#include "drivers/synth/scene_model.h"

namespace plumb::synth {

constexpr double kCorridorWidth = 2.4, kCorridorHeight = 2.8, kCorridorModuleLength = 3.0;
constexpr int kCorridorModules = 12;  // 36 m
constexpr double kCorridorLength = kCorridorModules * kCorridorModuleLength;

struct CorridorLayoutOptions {
  uint64_t seed = 1;  // the module template, the colours and the signs
  double wall_texels_per_metre = 150;
  double object_texels_per_metre = 220;
  double lightmap_texels_per_metre = 16;
};

SceneModel buildCorridor(const CorridorLayoutOptions& options);

}  // namespace plumb::synth
