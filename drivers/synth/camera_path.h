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
//   laps:     laps > 1 goes around `laps` times per period; every term above then repeats each
//             lap, and `lap_variation` adds terms at the period frequency (half the lap frequency
//             for 2 laps), so lap 2 passes a few centimetres and degrees beside lap 1 (a revisit,
//             not a replay) and the whole path still closes exactly after period_s
//   gaze:     kAcrossRoom (above) or kAtWall: the target lies `wall_gaze_distance_m` outward
//             from the camera, turned `wall_gaze_lead_rad` towards the direction of travel, so the
//             camera sweeps the walls at 1-2 m as it circles
#include <cstdint>

#include <Eigen/Geometry>

namespace plumb::synth {

enum class PathGaze { kAcrossRoom, kAtWall };

struct CameraPathOptions {
  uint64_t seed = 1;            // phases of every sinusoid and the starting angle on the loop
  double period_s = 20.0;       // the whole path (laps laps); it repeats after that
  double rotation_scale = 1.0;  // 1: hand-held; 2: "fast_rotation"
  Eigen::Vector3d centre_world = Eigen::Vector3d(3.75, 3.0, 0.0);  // floor point the path circles
  int laps = 1;                 // times around per period
  double lap_variation_m = 0.0;  // amplitude of the terms that make laps differ (0: identical laps)
  double radius_x_m = 1.8, radius_y_m = 1.3;  // ellipse radii
  PathGaze gaze = PathGaze::kAcrossRoom;
  double wall_gaze_distance_m = 2.0;  // kAtWall: how far out the gaze target lies
  double wall_gaze_lead_rad = 0.5;    // kAtWall: target turned this far towards the travel direction
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
  Wave radius_[3], height_[3], target_x_[3], target_y_[3], target_z_[2], roll_[2], yaw_[1], pitch_[1];
};

}  // namespace plumb::synth
