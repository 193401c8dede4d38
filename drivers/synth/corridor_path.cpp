// One-way camera path down the corridor (see corridor_path.h).
#include "drivers/synth/corridor_path.h"

#include <algorithm>
#include <cmath>

#include "drivers/synth/corridor_layout.h"
#include "drivers/synth/synth_random.h"

namespace plumb::synth {
namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr double kStartX = 1.5, kStopBeforeEnd = 2.5;
}  // namespace

CorridorPath::CorridorPath(const CorridorPathOptions& options) : options_(options) {
  SplitMix64 rng(mix64(options.seed ^ 0x436f72506174ULL));
  for (double& p : phase_) p = rng.uniform(0, 2 * M_PI);
}

Eigen::Isometry3d CorridorPath::T_world_cam(double t_s) const {
  auto wave = [&](double amplitude, double period_s, int k) {
    return amplitude * std::sin(2 * M_PI * t_s / period_s + phase_[k]);
  };
  const double travel = std::min(options_.speed_mps * std::max(t_s, 0.0), kCorridorLength - kStopBeforeEnd - kStartX);
  const Eigen::Vector3d p_world_cam(kStartX + travel, kCorridorWidth / 2 + wave(0.15, 11.0, 0),
                                    1.4 + wave(0.06, 7.0, 1));
  // Camera optical frame looking along +x: x right = -y world, y down = -z world, z forward = +x.
  Eigen::Matrix3d R_world_along;
  R_world_along << 0, 0, 1,  //
      -1, 0, 0,              //
      0, -1, 0;
  const double yaw = 45 * kDeg + wave(30 * kDeg, 13.0, 2) + wave(1.0 * kDeg, 0.9, 3);  // towards +y (north)
  const double pitch = -6 * kDeg + wave(4 * kDeg, 9.0, 4) + wave(0.8 * kDeg, 1.1, 5);
  const double roll = wave(3 * kDeg, 6.0, 6);
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_world_along *
                         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_cam.translation() = p_world_cam;
  return T_world_cam;
}

}  // namespace plumb::synth
