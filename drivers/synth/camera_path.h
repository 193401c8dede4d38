#pragma once
// The synthetic camera's trajectory: a smooth closed loop around the middle of the room, gazing
// across it (the table in the lower part of the view, furniture along the far wall 2-7 m away
// above it), with hand-held-like wobble.
//
// Every term is a sinusoid whose frequency is an integer multiple of 1 / period_s, so the path is
// C-infinity and exactly periodic: a run longer than one lap repeats it without a seam.
//   position: ellipse with radii 1.8 m x 1.3 m around the room centre, radius wobble +-0.14 m,
//             height 1.35 m +-0.13 m (one lap ~10 m: ~0.5 m/s with the default 20 s period)
//   gaze:     a target 0.6x the camera-centre distance beyond the centre, at 0.9 m height,
//             wandering +-0.45 m slowly, plus ~1 Hz hand jitter; roll +-5.5 deg
//   fast:     rotation_scale > 1 scales the gaze wander, jitter and roll and adds yaw / pitch
//             swings of +-14*scale / +-4*scale deg at 0.25 / 0.35 Hz (period 20 s)
#include <cstdint>

#include <Eigen/Geometry>

namespace plumb::synth {

struct CameraPathOptions {
  uint64_t seed = 1;            // phases of every sinusoid and the starting angle on the loop
  double period_s = 20.0;       // one lap
  double rotation_scale = 1.0;  // 1: hand-held; 2: "fast_rotation"
  Eigen::Vector3d centre_world = Eigen::Vector3d(3.75, 3.0, 0.0);  // floor point the path circles
};

class CameraPath {
 public:
  explicit CameraPath(const CameraPathOptions& options);
  // Camera pose at time t (seconds from the start); camera optical frame x right, y down, z forward.
  Eigen::Isometry3d T_world_cam(double t_s) const;

 private:
  // sum of amplitude * sin(2 pi harmonic t / period + phase)
  struct Wave {
    double amplitude;
    int harmonic;
    double phase;
  };
  double wave(const Wave* waves, int count, double t_s) const;

  CameraPathOptions options_;
  double start_angle_ = 0;
  Wave radius_[2], height_[2], target_x_[2], target_y_[2], target_z_[2], roll_[2], yaw_[1], pitch_[1];
};

}  // namespace plumb::synth
