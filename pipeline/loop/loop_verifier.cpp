#include "pipeline/loop/loop_verifier.h"

#include <array>

#include "solver/pose_optimizer.h"

namespace plumb::loop {

const char* toString(LoopRejection r) {
  switch (r) {
    case LoopRejection::kNone:
      return "accepted";
    case LoopRejection::kFewMatches:
      return "few_matches";
    case LoopRejection::kFewInliers:
      return "few_inliers";
    case LoopRejection::kLowInlierRatio:
      return "low_inlier_ratio";
    case LoopRejection::kRefinement:
      return "refinement";
    case LoopRejection::kImplausible:
      return "implausible_correction";
  }
  return "?";
}

struct LoopVerifier::Scratch {
  std::array<uint16_t, kMaxLoopPoints> query_index{};  // per match
  std::array<Eigen::Vector3d, kMaxLoopPoints> from{};  // query camera
  std::array<Eigen::Vector3d, kMaxLoopPoints> to{};    // candidate camera
  std::array<bool, kMaxLoopPoints> ransac_scratch{};
  std::array<bool, kMaxLoopPoints> inlier{};
  std::array<PosePointObservation, kMaxLoopPoints> pose_points{};
  std::array<bool, kMaxLoopPoints> pose_point_inlier{};
  std::array<PoseLineObservation, kMaxLoopLines * kMaxLineSamples> pose_lines{};
  std::array<bool, kMaxLoopLines * kMaxLineSamples> pose_line_inlier{};
};

LoopVerifier::LoopVerifier(const CameraIntrinsics& camera, const NoiseModelOptions& noise,
                           const LoopVerifierOptions& options)
    : camera_(camera), noise_(noise), options_(options), s_(std::make_unique<Scratch>()) {}

LoopVerifier::~LoopVerifier() = default;

namespace {

// Index of the best descriptor in [0, n) for d if it passes the threshold and ratio test, else -1.
int bestMatch(const Descriptor256& d, const Descriptor256* others, std::size_t n, int threshold,
              float ratio) {
  int best = 256, second = 256, best_index = -1;
  for (std::size_t j = 0; j < n; ++j) {
    const int dist = hammingDistance(d, others[j]);
    if (dist < best) {
      second = best;
      best = dist;
      best_index = int(j);
    } else if (dist < second) {
      second = dist;
    }
  }
  if (best_index < 0 || best > threshold || float(best) >= ratio * float(second)) return -1;
  return best_index;
}

}  // namespace

LoopMeasurement LoopVerifier::verify(const LoopKeyframe& query, const LoopCandidate& candidate) {
  LoopMeasurement m;
  Scratch& s = *s_;
  // 1. Points.
  int n = 0;
  for (std::size_t k = 0; k < query.points.size(); ++k) {
    const int j = bestMatch(query.point_descriptors[k], candidate.point_descriptors.data(),
                            candidate.num_points, options_.hamming_threshold, options_.ratio);
    if (j < 0) continue;
    s.query_index[std::size_t(n)] = uint16_t(k);
    s.from[std::size_t(n)] = query.points[k].P_cam.cast<double>();
    s.to[std::size_t(n)] = candidate.P_cam[std::size_t(j)].cast<double>();
    ++n;
  }
  m.matches = n;
  if (n < options_.min_matches) return m;

  // 2. Rigid RANSAC: T_candidate_query maps query-camera points onto candidate-camera points.
  Eigen::Isometry3d T_cq = Eigen::Isometry3d::Identity();
  m.ransac_inliers = rigidRansac(s.from.data(), s.to.data(), n, options_.ransac, s.ransac_scratch.data(),
                                 s.inlier.data(), &T_cq);
  if (m.ransac_inliers < options_.min_inliers) {
    m.rejection = LoopRejection::kFewInliers;
    return m;
  }
  if (double(m.ransac_inliers) < options_.min_inlier_ratio * double(n)) {
    m.rejection = LoopRejection::kLowInlierRatio;
    return m;
  }

  // 3. Refinement: candidate camera = "world", query = the camera being posed.
  int num_points = 0;
  for (int i = 0; i < n; ++i) {
    if (!s.inlier[std::size_t(i)]) continue;
    const LoopPoint& q = query.points[s.query_index[std::size_t(i)]];
    PosePointObservation& obs = s.pose_points[std::size_t(num_points++)];
    obs.P_world = s.to[std::size_t(i)];
    obs.has_depth = true;
    obs.z = Eigen::Vector3d(q.px.x(), q.px.y(), q.u_right);
    obs.information = stereoPointInformation(noise_, camera_, q.octave, q.P_cam.z());
    if (!(obs.information.trace() > 0)) {
      obs.has_depth = false;
      obs.information.setZero();
      obs.information.topLeftCorner<2, 2>() = monoPointInformation(noise_, q.octave);
    }
  }
  int num_lines = 0;
  if (options_.use_lines) {
    for (std::size_t k = 0; k < query.lines.size(); ++k) {
      const int j =
          bestMatch(query.line_descriptors[k], candidate.line_descriptors.data(), candidate.num_lines,
                    options_.line_hamming_threshold, options_.line_ratio);
      if (j < 0) continue;
      ++m.line_matches;
      const std::size_t first = candidate.first_sample[std::size_t(j)];
      const LoopLine& q = query.lines[k];
      for (std::size_t smp = 0; smp < candidate.num_samples[std::size_t(j)]; ++smp) {
        PoseLineObservation& obs = s.pose_lines[std::size_t(num_lines++)];
        obs.P_world = candidate.samples_cam[first + smp].cast<double>();
        obs.line = q.l.cast<double>();
        obs.information = lineSampleInformation(noise_, q.octave);
      }
    }
  }
  PoseOptimizerOptions pose_options;
  const PoseResult pose = optimizePose(
      camera_, T_cq.inverse(), s.pose_points.data(), num_points, s.pose_lines.data(), num_lines, pose_options,
      s.pose_point_inlier.data(), num_lines > 0 ? s.pose_line_inlier.data() : nullptr);
  m.refined_inliers = pose.num_point_inliers;
  m.line_inliers = pose.num_line_inliers;
  if (m.refined_inliers < options_.min_refined_inliers || !pose.covariance_valid) {
    m.rejection = LoopRejection::kRefinement;
    return m;
  }
  m.T_candidate_query = pose.T_cam_world.inverse();
  m.covariance = pose.covariance;
  m.rejection = LoopRejection::kNone;
  return m;
}

}  // namespace plumb::loop
