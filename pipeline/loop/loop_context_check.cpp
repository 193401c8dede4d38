#include "pipeline/loop/loop_context_check.h"

#include <algorithm>
#include <array>

namespace plumb::loop {

struct LoopContextCheck::Scratch {
  // Best and second-best distance per point of either keyframe of a pair, and the best's index.
  std::array<int, kMaxLoopPoints> best_i{}, second_i{}, index_i{};
  std::array<int, kMaxLoopPoints> best_j{}, second_j{}, index_j{};
};

LoopContextCheck::LoopContextCheck(const CameraIntrinsics& camera, const LoopContextCheckOptions& options)
    : camera_(camera), options_(options), s_(std::make_unique<Scratch>()) {}

LoopContextCheck::~LoopContextCheck() = default;

std::size_t LoopContextCheck::scratchBytes() { return sizeof(Scratch); }

LoopContextResult LoopContextCheck::evaluate(const LoopContextSide& query, const LoopContextSide& candidate) {
  LoopContextResult r;
  Scratch& s = *s_;
  const double tau2 = options_.truncation_px * options_.truncation_px;
  const double inv_sigma2 = 1.0 / (options_.pixel_sigma * options_.pixel_sigma);
  const double inlier2 = 4.0 * options_.pixel_sigma * options_.pixel_sigma;
  auto pixel = [this](const Eigen::Vector3d& P) {
    return Eigen::Vector2d(camera_.fx * P.x() / P.z() + camera_.cx, camera_.fy * P.y() / P.z() + camera_.cy);
  };
  for (int qi = 0; qi < query.count; ++qi) {
    for (int cj = 0; cj < candidate.count; ++cj) {
      if (qi == 0 && cj == 0) continue;  // the verified pair
      const LoopCandidate& a = *query.records[qi];
      const LoopCandidate& b = *candidate.records[cj];
      if (a.num_points == 0 || b.num_points == 0) continue;
      ++r.pairs;
      std::fill_n(s.best_i.begin(), a.num_points, 257);
      std::fill_n(s.second_i.begin(), a.num_points, 257);
      std::fill_n(s.best_j.begin(), b.num_points, 257);
      std::fill_n(s.second_j.begin(), b.num_points, 257);
      for (int k = 0; k < a.num_points; ++k) {
        for (int l = 0; l < b.num_points; ++l) {
          const int d = hammingDistance(a.point_descriptors[std::size_t(k)], b.point_descriptors[std::size_t(l)]);
          if (d < s.best_i[std::size_t(k)]) {
            s.second_i[std::size_t(k)] = s.best_i[std::size_t(k)];
            s.best_i[std::size_t(k)] = d;
            s.index_i[std::size_t(k)] = l;
          } else if (d < s.second_i[std::size_t(k)]) {
            s.second_i[std::size_t(k)] = d;
          }
          if (d < s.best_j[std::size_t(l)]) {
            s.second_j[std::size_t(l)] = s.best_j[std::size_t(l)];
            s.best_j[std::size_t(l)] = d;
            s.index_j[std::size_t(l)] = k;
          } else if (d < s.second_j[std::size_t(l)]) {
            s.second_j[std::size_t(l)] = d;
          }
        }
      }
      // Relative poses of the pair: i's camera points into j's camera, before and after.
      const Eigen::Isometry3d T_ji_before = candidate.T_world_before[cj].inverse() * query.T_world_before[qi];
      const Eigen::Isometry3d T_ji_after = candidate.T_world_after[cj].inverse() * query.T_world_after[qi];
      for (int k = 0; k < a.num_points; ++k) {
        const int l = s.index_i[std::size_t(k)];
        const int d = s.best_i[std::size_t(k)];
        if (d > options_.hamming_threshold || float(d) >= options_.ratio * float(s.second_i[std::size_t(k)])) continue;
        if (s.index_j[std::size_t(l)] != k) continue;  // mutual best only
        ++r.matches;
        const Eigen::Vector3d P_i = a.P_cam[std::size_t(k)].cast<double>();
        const Eigen::Vector3d P_j = b.P_cam[std::size_t(l)].cast<double>();
        const Eigen::Vector2d observed = pixel(P_j);  // j's keypoint (its point is its back-projection)
        const auto cost = [&](const Eigen::Isometry3d& T_ji, int* inliers) {
          const Eigen::Vector3d X = T_ji * P_i;
          if (!(X.z() > 0.05)) return tau2 * inv_sigma2;
          const double e2 = (pixel(X) - observed).squaredNorm();
          *inliers += e2 <= inlier2 ? 1 : 0;
          return std::min(e2, tau2) * inv_sigma2;
        };
        r.cost_before += cost(T_ji_before, &r.inliers_before);
        r.cost_after += cost(T_ji_after, &r.inliers_after);
      }
    }
  }
  return r;
}

}  // namespace plumb::loop
