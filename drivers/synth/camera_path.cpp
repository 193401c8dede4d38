// Smooth periodic camera path (see camera_path.h).
#include "drivers/synth/camera_path.h"

#include <cmath>

#include "drivers/synth/synth_random.h"

namespace plumb::synth {
namespace {
constexpr double kDeg = M_PI / 180.0;
// The gaze target lies this fraction of the camera-to-centre distance beyond the centre.
constexpr double kLookAcross = 0.6;
}

CameraPath::CameraPath(const CameraPathOptions& options) : options_(options) {
  SplitMix64 rng(mix64(options.seed ^ 0x50617468ULL));
  auto phase = [&rng]() { return rng.uniform(0, 2 * M_PI); };
  const double s = options.rotation_scale;
  // Harmonics are per lap: with several laps per period each term repeats every lap.
  const int l = options.laps;
  start_angle_ = phase();
  radius_[0] = {0.10, 4 * l, phase()};
  radius_[1] = {0.04, 9 * l, phase()};
  height_[0] = {0.10, 3 * l, phase()};
  height_[1] = {0.03, 11 * l, phase()};
  // Slow gaze wander (metres at the target) and fast hand jitter.
  target_x_[0] = {0.45 * s, 2 * l, phase()};
  target_x_[1] = {0.05 * s, 17 * l, phase()};
  target_y_[0] = {0.35 * s, 3 * l, phase()};
  target_y_[1] = {0.05 * s, 19 * l, phase()};
  target_z_[0] = {0.25, 5 * l, phase()};
  target_z_[1] = {0.04 * s, 23 * l, phase()};
  roll_[0] = {4.0 * kDeg * s, 3 * l, phase()};
  roll_[1] = {1.5 * kDeg * s, 13 * l, phase()};
  // Extra swings only when asked for faster rotation.
  const double extra = s > 1 ? s : 0;
  yaw_[0] = {14.0 * kDeg * extra, 5 * l, phase()};
  pitch_[0] = {4.0 * kDeg * extra, 7 * l, phase()};
  // Lap-to-lap differences: once per period (drawn last, so single-lap paths keep their phases;
  // with amplitude 0 they add exactly 0).
  const double v = options.lap_variation_m;
  radius_[2] = {v, 1, phase()};
  height_[2] = {0.5 * v, 1, phase()};
  target_x_[2] = {2.0 * v, 1, phase()};
  target_y_[2] = {2.0 * v, 1, phase()};
}

double CameraPath::wave(const Wave* waves, int count, double t_s) const {
  double sum = 0;
  for (int i = 0; i < count; ++i)
    sum += waves[i].amplitude * std::sin(2 * M_PI * waves[i].harmonic * t_s / options_.period_s + waves[i].phase);
  return sum;
}

Eigen::Isometry3d CameraPath::T_world_cam(double t_s) const {
  const Eigen::Vector3d& c = options_.centre_world;
  const double angle = start_angle_ + 2 * M_PI * options_.laps * t_s / options_.period_s;
  const double wobble = wave(radius_, 3, t_s);
  const Eigen::Vector3d p_world_cam(c.x() + (options_.radius_x_m + wobble) * std::cos(angle),
                                    c.y() + (options_.radius_y_m + wobble) * std::sin(angle),
                                    1.35 + wave(height_, 3, t_s));
  Eigen::Vector3d target_world;
  if (options_.gaze == PathGaze::kAcrossRoom) {
    // Gaze across the room: a target beyond the centre keeps the table in the lower part of the
    // view and the furniture along the far wall in the upper part.
    const Eigen::Vector2d across = (c.head<2>() - p_world_cam.head<2>()) * kLookAcross;
    target_world = Eigen::Vector3d(c.x() + across.x() + wave(target_x_, 3, t_s),
                                   c.y() + across.y() + wave(target_y_, 3, t_s), 0.9 + wave(target_z_, 2, t_s));
  } else {
    // Gaze at the nearest wall, turned towards the direction of travel (the angle grows, so
    // travel is counter-clockwise seen from above).
    const double a = angle + options_.wall_gaze_lead_rad;
    const double d = options_.wall_gaze_distance_m;
    target_world = Eigen::Vector3d(p_world_cam.x() + d * std::cos(a) + wave(target_x_, 3, t_s),
                                   p_world_cam.y() + d * std::sin(a) + wave(target_y_, 3, t_s),
                                   1.1 + wave(target_z_, 2, t_s));
  }
  // Look-at frame: forward to the target, right horizontal, down completing x right, y down, z forward.
  const Eigen::Vector3d forward = (target_world - p_world_cam).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d R_world_look;
  R_world_look << right, down, forward;
  // Yaw about the world vertical, then pitch (camera x) and roll (camera z) in the camera frame.
  const Eigen::Matrix3d R_world_cam =
      Eigen::AngleAxisd(wave(yaw_, 1, t_s), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_world_look *
      Eigen::AngleAxisd(wave(pitch_, 1, t_s), Eigen::Vector3d::UnitX()).toRotationMatrix() *
      Eigen::AngleAxisd(wave(roll_, 2, t_s), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() = R_world_cam;
  T_world_cam.translation() = p_world_cam;
  return T_world_cam;
}

}  // namespace plumb::synth
