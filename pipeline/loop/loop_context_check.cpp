#include "pipeline/loop/loop_context_check.h"

#include <algorithm>
#include <array>

#include "pipeline/frontend/descriptor_match.h"

namespace plumb::loop {

struct LoopContextCheck::Scratch {
  // Per point of the query-side keyframe of a pair: its two nearest on the candidate side (below
  // the ratio bound); per point of the candidate side: its nearest on the query side (below the
  // Hamming threshold + 1) and that one's index.
  std::array<NearestTwo, kMaxLoopPoints> rows{};
  std::array<int, kMaxLoopPoints> col_best{}, col_index{};
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
  const int row_bound = ratioBound(options_.hamming_threshold, options_.ratio, 257);
  const int col_bound = std::min(std::max(options_.hamming_threshold, -1) + 1, 257);
  for (int qi = 0; qi < query.count; ++qi) {
    for (int cj = 0; cj < candidate.count; ++cj) {
      if (qi == 0 && cj == 0) continue;  // the verified pair
      const LoopCandidate& a = *query.records[qi];
      const LoopCandidate& b = *candidate.records[cj];
      if (a.num_points == 0 || b.num_points == 0) continue;
      ++r.pairs;
      // Both ways in one pass over the pairs (pipeline/frontend/descriptor_match.h). A row's match
      // is decided by its best within the threshold and the ratio test, which scanning below
      // ratioBound() keeps exact; a column is read only at a row's best within the threshold, so
      // only column distances <= threshold matter (the mutual-best test compares indices).
      nearestBothWays(a.point_descriptors.data(), a.num_points, b.point_descriptors.data(), b.num_points, row_bound,
                      col_bound, s.rows.data(), s.col_best.data(), s.col_index.data());
      // Relative poses of the pair: i's camera points into j's camera, before and after.
      const Eigen::Isometry3d T_ji_before = candidate.T_world_before[cj].inverse() * query.T_world_before[qi];
      const Eigen::Isometry3d T_ji_after = candidate.T_world_after[cj].inverse() * query.T_world_after[qi];
      for (int k = 0; k < a.num_points; ++k) {
        const NearestTwo& row = s.rows[std::size_t(k)];
        const int d = row.best;
        if (d > options_.hamming_threshold || float(d) >= options_.ratio * float(row.second)) continue;
        const int l = row.best_index;
        if (s.col_index[std::size_t(l)] != k) continue;  // mutual best only
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
