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
  start_angle_ = phase();
  radius_[0] = {0.10, 4, phase()};
  radius_[1] = {0.04, 9, phase()};
  height_[0] = {0.10, 3, phase()};
  height_[1] = {0.03, 11, phase()};
  // Slow gaze wander (metres at the target) and fast hand jitter.
  target_x_[0] = {0.45 * s, 2, phase()};
  target_x_[1] = {0.05 * s, 17, phase()};
  target_y_[0] = {0.35 * s, 3, phase()};
  target_y_[1] = {0.05 * s, 19, phase()};
  target_z_[0] = {0.25, 5, phase()};
  target_z_[1] = {0.04 * s, 23, phase()};
  roll_[0] = {4.0 * kDeg * s, 3, phase()};
  roll_[1] = {1.5 * kDeg * s, 13, phase()};
  // Extra swings only when asked for faster rotation.
  const double extra = s > 1 ? s : 0;
  yaw_[0] = {14.0 * kDeg * extra, 5, phase()};
  pitch_[0] = {4.0 * kDeg * extra, 7, phase()};
}

double CameraPath::wave(const Wave* waves, int count, double t_s) const {
  double sum = 0;
  for (int i = 0; i < count; ++i)
    sum += waves[i].amplitude * std::sin(2 * M_PI * waves[i].harmonic * t_s / options_.period_s + waves[i].phase);
  return sum;
}

Eigen::Isometry3d CameraPath::T_world_cam(double t_s) const {
  const Eigen::Vector3d& c = options_.centre_world;
  const double angle = start_angle_ + 2 * M_PI * t_s / options_.period_s;
  const double wobble = wave(radius_, 2, t_s);
  const Eigen::Vector3d p_world_cam(c.x() + (1.8 + wobble) * std::cos(angle),
                                    c.y() + (1.3 + wobble) * std::sin(angle), 1.35 + wave(height_, 2, t_s));
  // Gaze across the room: a target beyond the centre keeps the table in the lower part of the view
  // and the furniture along the far wall in the upper part.
  const Eigen::Vector2d across = (c.head<2>() - p_world_cam.head<2>()) * kLookAcross;
  const Eigen::Vector3d target_world(c.x() + across.x() + wave(target_x_, 2, t_s),
                                     c.y() + across.y() + wave(target_y_, 2, t_s), 0.9 + wave(target_z_, 2, t_s));
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
