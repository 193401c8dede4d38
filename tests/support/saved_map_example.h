#pragma once
// A made-up but valid SavedMap (pipeline/loop/saved_map.h) for the map file tests and the fuzzer's
// seed corpus (fuzz/make_map_seeds.cpp): every field filled from a portable generator (SplitMix64,
// so the bytes are the same on every platform), rotations orthonormal, covariances positive
// definite, ids ascending, loop edges between stored keyframes.
#include <cmath>
#include <cstdint>
#include <memory>

#include <Eigen/Geometry>

#include "pipeline/loop/saved_map.h"

namespace plumb::test {

class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * double(next() >> 11) * 0x1.0p-53; }

 private:
  uint64_t state_;
};

inline PinholeCamera exampleMapCamera() {
  PinholeCamera c;
  c.fx = 517.3;
  c.fy = 516.5;
  c.cx = 318.6;
  c.cy = 255.3;
  c.k1 = 0.2624;
  c.width = 640;
  c.height = 480;
  return c;
}

inline Eigen::Isometry3d randomPose(SplitMix64& g) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d axis = Eigen::Vector3d(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1)).normalized();
  T.linear() = Eigen::AngleAxisd(g.uniform(-3, 3), axis).toRotationMatrix();
  T.translation() = Eigen::Vector3d(g.uniform(-2, 2), g.uniform(-2, 2), g.uniform(-2, 2));
  return T;
}

inline Matrix6d randomSpd(SplitMix64& g, double scale) {
  Matrix6d A;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) A(r, c) = g.uniform(-1, 1);
  return scale * (A * A.transpose() + 0.1 * Matrix6d::Identity());
}

inline Descriptor256 randomDescriptor(SplitMix64& g) {
  Descriptor256 d;
  for (uint64_t& w : d.words) w = g.next();
  return d;
}

// `keyframes` keyframes with `points` points and `lines` lines each, `loop_edges` loop edges.
inline void makeExampleMap(uint64_t seed, int keyframes, int points, int lines, int loop_edges, loop::SavedMap* map) {
  SplitMix64 g(seed);
  map->camera = exampleMapCamera();
  map->keyframes.clear();
  map->loop_edges.clear();
  for (int i = 0; i < keyframes; ++i) {
    auto k = std::make_unique<loop::SavedKeyframe>();
    loop::LoopKeyframe& r = k->record;
    r.id = uint32_t(1 + 3 * i);
    r.frame_sequence = uint64_t(10 * i);
    r.timestamp_s = 1305031102.175304 + 0.3 * i;
    r.new_segment = i == 0;
    r.previous_id = i == 0 ? 0 : uint32_t(1 + 3 * (i - 1));
    r.T_previous_this = randomPose(g);
    r.T_world_cam = randomPose(g);
    r.covariance = randomSpd(g, 1e-5);
    r.covariance_valid = (i % 3) != 2;
    k->T_world_cam = randomPose(g);
    k->has_edge = i > 0;
    k->T_previous_this = randomPose(g);
    k->edge_covariance = randomSpd(g, 1e-4);
    k->edge_length_m = g.uniform(0, 0.5);
    k->previous_map_id = r.previous_id;
    for (int p = 0; p < points; ++p) {
      loop::LoopPoint lp;
      lp.P_cam = Eigen::Vector3f(float(g.uniform(-2, 2)), float(g.uniform(-1.5, 1.5)), float(g.uniform(0.5, 4)));
      lp.px = Eigen::Vector2f(float(g.uniform(0, 640)), float(g.uniform(0, 480)));
      lp.u_right = lp.px.x() - float(g.uniform(1, 80));
      lp.octave = int8_t(g.next() % kPyramidLevels);
      (void)r.points.push_back(lp);
      (void)r.point_descriptors.push_back(randomDescriptor(g));
    }
    for (int l = 0; l < lines; ++l) {
      loop::LoopLine ll;
      ll.l = Eigen::Vector3f(float(g.uniform(-1, 1)), float(g.uniform(-1, 1)), float(g.uniform(-300, 300)));
      ll.octave = int8_t(g.next() % 3);
      ll.num_samples = uint8_t(2 + g.next() % (kMaxLineSamples - 1));
      for (std::size_t s = 0; s < ll.num_samples; ++s) {
        ll.samples_cam[s] = Eigen::Vector3f(float(g.uniform(-2, 2)), float(g.uniform(-2, 2)), float(g.uniform(0.5, 4)));
      }
      (void)r.lines.push_back(ll);
      (void)r.line_descriptors.push_back(randomDescriptor(g));
    }
    // What a loop closer keeps of a record (its LoopCandidate and graph node) is all a map file
    // can give back: the header fields and the query-only feature fields are not kept, so a map
    // exported by a closer has them at their defaults (docs/LOOP.md "Map files"). The example is
    // made the same way, so that a round trip through a closer is byte-exact.
    r.frame_sequence = 0;
    r.timestamp_s = 0;
    r.new_segment = false;
    r.covariance.setZero();
    r.covariance_valid = false;
    r.T_previous_this = k->T_previous_this;
    for (loop::LoopPoint& lp : r.points) {
      lp.px.setZero();
      lp.u_right = 0;
      lp.octave = 0;
    }
    for (loop::LoopLine& ll : r.lines) {
      ll.l.setZero();
      ll.octave = 0;
    }
    map->keyframes.push_back(std::move(k));
  }
  for (int e = 0; e < loop_edges && keyframes >= 2; ++e) {
    loop::SavedLoopEdge edge;
    edge.candidate_id = map->keyframes[std::size_t(e) % std::size_t(keyframes - 1)]->record.id;
    edge.query_id = map->keyframes.back()->record.id;
    edge.T_candidate_query = randomPose(g);
    edge.information = randomSpd(g, 1e3);
    map->loop_edges.push_back(edge);
  }
}

}  // namespace plumb::test
