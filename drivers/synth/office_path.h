#pragma once
// The camera path of "office_pass" (office_layout.h): one way along the row of identical
// workstations on the south wall, never back, so there is no real loop however alike the
// workstations look (the office's counterpart of the corridor, corridor_path.h).
//
//   position: from x = 1.2 m along +x at `speed_mps` (0.25 m/s) at y = 2.5 m (+-0.1 m sway),
//             1.4 m high (+-0.05 m bob); it stops at x = 7.8 m (after 26.4 s, frame ~790 at
//             30 fps) and stays there
//   gaze:     towards the south wall (desks, chairs, windows), turned 30 deg +- 25 deg towards
//             the direction of travel, pitched ~15 deg down, +-3 deg roll, ~1 Hz hand jitter
// Smooth everywhere except the stop at the end (a step in velocity).
#include <cstdint>

#include <Eigen/Geometry>

namespace plumb::synth {

struct OfficePathOptions {
  uint64_t seed = 1;
  double speed_mps = 0.25;
};

class OfficePassPath {
 public:
  explicit OfficePassPath(const OfficePathOptions& options);
  Eigen::Isometry3d T_world_cam(double t_s) const;

 private:
  OfficePathOptions options_;
  double phase_[7] = {0, 0, 0, 0, 0, 0, 0};
};

}  // namespace plumb::synth
