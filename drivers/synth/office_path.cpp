// One-way camera path along the office's workstations (see office_path.h).
#include "drivers/synth/office_path.h"

#include <algorithm>
#include <cmath>

#include "drivers/synth/synth_random.h"

namespace plumb::synth {
namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr double kStartX = 1.2, kStopX = 7.8;
}  // namespace

OfficePassPath::OfficePassPath(const OfficePathOptions& options) : options_(options) {
  SplitMix64 rng(mix64(options.seed ^ 0x4f66506173ULL));
  for (double& p : phase_) p = rng.uniform(0, 2 * M_PI);
}

Eigen::Isometry3d OfficePassPath::T_world_cam(double t_s) const {
  auto wave = [&](double amplitude, double period_s, int k) {
    return amplitude * std::sin(2 * M_PI * t_s / period_s + phase_[k]);
  };
  const double travel = std::min(options_.speed_mps * std::max(t_s, 0.0), kStopX - kStartX);
  const Eigen::Vector3d p_world_cam(kStartX + travel, 2.5 + wave(0.1, 11.0, 0), 1.4 + wave(0.05, 7.0, 1));
  // Optical frame looking along -y (south): x right = -x world, y down = -z world, z forward = -y.
  Eigen::Matrix3d R_world_south;
  R_world_south << -1, 0, 0,  //
      0, 0, -1,               //
      0, -1, 0;
  // Yaw about the vertical, positive turns the gaze from -y towards +x (the travel direction).
  const double yaw = 30 * kDeg + wave(25 * kDeg, 9.0, 2) + wave(1.0 * kDeg, 0.9, 3);
  const double pitch = -15 * kDeg + wave(5 * kDeg, 8.0, 4) + wave(0.8 * kDeg, 1.1, 5);
  const double roll = wave(3 * kDeg, 6.0, 6);
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_world_south *
                         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_cam.translation() = p_world_cam;
  return T_world_cam;
}

}  // namespace plumb::synth
