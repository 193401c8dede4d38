#pragma once
// The camera path of the "repeated" corridor (corridor_layout.h): one way down the corridor, never
// back, so there is no real loop to find however alike the modules look.
//
//   position: from x = 1.5 m along +x at `speed_mps` (0.45 m/s), in the middle of the width
//             (+-0.15 m sway), at 1.4 m (+-0.06 m bob); it stops at 2.5 m before the far end
//             (36 m corridor: after ~71 s, frame ~2130 at 30 fps) and stays there
//   gaze:     turned 45 deg +- 30 deg from the corridor axis towards the north wall (doors and
//             signs), pitched ~6 deg down, +-3 deg roll, ~1 Hz hand jitter
// Smooth everywhere except the stop at the end (a step in velocity).
#include <cstdint>

#include <Eigen/Geometry>

namespace plumb::synth {

struct CorridorPathOptions {
  uint64_t seed = 1;
  double speed_mps = 0.45;
};

class CorridorPath {
 public:
  explicit CorridorPath(const CorridorPathOptions& options);
  Eigen::Isometry3d T_world_cam(double t_s) const;

 private:
  CorridorPathOptions options_;
  double phase_[7] = {0, 0, 0, 0, 0, 0, 0};
};

}  // namespace plumb::synth
