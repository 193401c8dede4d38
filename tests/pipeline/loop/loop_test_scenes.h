#pragma once
// Scenes and keyframe records for the loop-closing tests, built on the odometry tests' hand-made
// FrameFeatures (tests/support/synthetic_features.h): no images, exact ground truth.
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "pipeline/loop/loop_keyframe.h"
#include "tests/support/synthetic_features.h"

namespace plumb::test {

// Points on the inside of a vertical cylinder (radius `radius`, height 0.6..2.4 m, z up), each with
// its own random descriptor: a room seen by a camera that circles its centre looking outward.
inline Scene cylinderScene(uint64_t seed, int num_points, double radius) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), height(0.6, 2.4), response(10, 100);
  Scene scene;
  for (int i = 0; i < num_points; ++i) {
    ScenePoint p;
    const double a = angle(rng);
    p.P_world = Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), height(rng));
    p.descriptor = randomDescriptor(rng);
    p.response = float(response(rng));
    scene.points.push_back(p);
  }
  return scene;
}

// A camera at (r cos a, r sin a, 1.5) looking outward (optical axis radial, y down = -z world).
inline Eigen::Isometry3d outwardPose(double a, double r) {
  const Eigen::Vector3d z(std::cos(a), std::sin(a), 0), y(0, 0, -1);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = y.cross(z);
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 1.5);
  return T;
}

// A record of `scene` seen from T_world_cam (true pose), with the given odometry fields.
inline std::unique_ptr<loop::LoopKeyframe> recordOf(const Scene& scene, uint32_t id,
                                                    const Eigen::Isometry3d& T_true,
                                                    const Eigen::Isometry3d& T_world_cam_odometry,
                                                    uint32_t previous_id,
                                                    const Eigen::Isometry3d& T_previous_this) {
  auto r = std::make_unique<loop::LoopKeyframe>();
  const View view = observe(scene, T_true);
  loop::fillLoopFeatures(*view.features, r.get());
  r->id = id;
  r->frame_sequence = id;
  r->timestamp_s = id;
  r->previous_id = previous_id;
  r->T_previous_this = T_previous_this;
  r->T_world_cam = T_world_cam_odometry;
  return r;
}

// What the closer stores of a record: the candidate side of verification.
inline std::unique_ptr<loop::LoopCandidate> candidateOf(const loop::LoopKeyframe& record) {
  auto c = std::make_unique<loop::LoopCandidate>();
  loop::makeLoopCandidate(record, c.get());
  return c;
}

}  // namespace plumb::test
