#pragma once
// Bakes the room's view-independent lighting into every face's texture, once per scene:
//   light(P) = ambient + sun_strength * max(0, -n . sun_dir)
//            + lamp_strength * max(0, n . (lamp - P) / |lamp - P|) / (1 + |lamp - P|^2 / 4)
// The sun term makes the faces of a box differ in brightness (strong edges even between equally
// coloured faces); the lamp adds smooth gradients that carry no corners. Untextured faces get a
// coarse light map (albedo x light) so that they too are a single bilinear lookup at render time.
#include "drivers/synth/scene_model.h"

namespace plumb::synth {

void bakeLighting(SceneModel& model, double lightmap_texels_per_metre);

}  // namespace plumb::synth
