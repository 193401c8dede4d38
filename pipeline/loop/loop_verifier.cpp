#include "pipeline/loop/loop_verifier.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "pipeline/frontend/descriptor_match.h"
#include "solver/factors.h"
#include "solver/pose_leverage.h"
#include "solver/pose_optimizer.h"
#include "solver/se3_jacobians.h"
#include "solver/variance_factor.h"

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
    case LoopRejection::kUncertain:
      return "uncertain";
    case LoopRejection::kRolledBack:
      return "rolled_back";
  }
  return "?";
}

// A query point matches one candidate point, or two when the ratio test cannot tell them apart.
constexpr std::size_t kMaxPointHypotheses = 2 * kMaxLoopPoints;

struct LoopVerifier::Scratch {
  std::array<uint16_t, kMaxPointHypotheses> query_index{};  // per hypothesis
  std::array<Eigen::Vector3d, kMaxPointHypotheses> from{};  // query camera
  std::array<Eigen::Vector3d, kMaxPointHypotheses> to{};    // candidate camera
  std::array<int8_t, kMaxPointHypotheses> candidate_octave{};
  std::array<bool, kMaxPointHypotheses> ransac_scratch{};
  std::array<bool, kMaxPointHypotheses> inlier{};
  std::array<PosePointObservation, kMaxLoopPoints> pose_points{};
  std::array<bool, kMaxLoopPoints> pose_point_inlier{};
  std::array<PoseLineObservation, kMaxLoopLines * kMaxLineSamples> pose_lines{};
  std::array<bool, kMaxLoopLines * kMaxLineSamples> pose_line_inlier{};
  // Reliability (weakestFeature): the line each sample belongs to (a line's samples are
  // contiguous), the union-find parent and root of each point observation (its feature).
  std::array<uint8_t, kMaxLoopLines * kMaxLineSamples> line_of_sample{};
  std::array<int16_t, kMaxLoopPoints> feature_parent{};
  std::array<bool, kMaxLoopPoints> keep{};
  std::array<Eigen::Vector2d, kMaxLoopPoints> candidate_px{};
  std::array<int16_t, kMaxLoopPoints> feature_root{};
  std::array<int16_t, kMaxLoopPoints> by_feature{};  // inliers ordered by (feature, index)
};
static_assert(kMaxLoopLines <= 256, "line_of_sample is a uint8_t");
static_assert(kMaxLoopPoints <= 32767, "feature_parent is an int16_t");

Eigen::Matrix3d LoopVerifier::candidateCovarianceInQuery(const Eigen::Vector3d& P_candidate, int octave,
                                                         const Eigen::Isometry3d& T_query_candidate) const {
  const double z = P_candidate.z();
  if (!options_.propagate_candidate_noise || !(z >= noise_.min_depth)) return Eigen::Matrix3d::Zero();
  // The candidate's pixel, from its 3D point (its own back-projection).
  const double u = camera_.fx * P_candidate.x() / z + camera_.cx;
  const double v = camera_.fy * P_candidate.y() / z + camera_.cy;
  const Eigen::Matrix3d R = T_query_candidate.linear();
  return R * backProjectedPointCovariance(noise_, camera_, u, v, z, octave) * R.transpose();
}

LoopVerifier::LoopVerifier(const CameraIntrinsics& camera, const NoiseModelOptions& noise,
                           const LoopVerifierOptions& options)
    : camera_(camera), noise_(noise), options_(options), s_(std::make_unique<Scratch>()) {}

LoopVerifier::~LoopVerifier() = default;

std::size_t LoopVerifier::scratchBytes() { return sizeof(Scratch); }

bool LoopVerifier::lineAgrees(const LoopLine& query_line, const Eigen::Vector3f* candidate_samples,
                              std::size_t count, const Eigen::Isometry3d& T_query_candidate) const {
  if (count < 2 || query_line.num_samples < 2) return false;
  const Eigen::Vector3d l = query_line.l.cast<double>();
  const Eigen::Vector2d direction(-l.y(), l.x());  // along the line (l is normalised: a^2 + b^2 = 1)
  auto pixel = [this](const Eigen::Vector3d& P) {
    return Eigen::Vector2d(camera_.fx * P.x() / P.z() + camera_.cx, camera_.fy * P.y() / P.z() + camera_.cy);
  };
  // Extent of the query segment along its line, from its own samples.
  double q_lo = INFINITY, q_hi = -INFINITY;
  for (std::size_t s = 0; s < query_line.num_samples; ++s) {
    const Eigen::Vector3d P = query_line.samples_cam[s].cast<double>();
    if (!(P.z() > 0)) continue;
    const double t = direction.dot(pixel(P));
    q_lo = std::min(q_lo, t);
    q_hi = std::max(q_hi, t);
  }
  const double gate = options_.line_gate_px * std::pow(1.2, std::max<int>(0, query_line.octave));  // ORB pyramid scale
  int close = 0;
  double c_lo = INFINITY, c_hi = -INFINITY;
  for (std::size_t s = 0; s < count; ++s) {
    const Eigen::Vector3d X = T_query_candidate * candidate_samples[s].cast<double>();
    if (!(X.z() > 0.05)) continue;
    const Eigen::Vector2d p = pixel(X);
    if (std::abs(l.dot(p.homogeneous())) <= gate) ++close;
    const double t = direction.dot(p);
    c_lo = std::min(c_lo, t);
    c_hi = std::max(c_hi, t);
  }
  const bool overlap = c_lo <= q_hi && q_lo <= c_hi;
  return overlap && double(close) >= options_.line_gate_min_fraction * double(count);
}

double LoopVerifier::weakestFeature(const PoseResult& pose, int num_points, int num_lines,
                                    const PoseOptimizerOptions& pose_options, int* feature) const {
  Scratch& s = *s_;
  auto root = [&s](int i) {
    while (s.feature_parent[std::size_t(i)] != i) i = s.feature_parent[std::size_t(i)];
    return i;
  };
  // Features: inliers whose query pixels or candidate pixels are within same_feature_px (union by
  // the smaller index, so the grouping does not depend on the visiting order).
  const double r2 = options_.same_feature_px * options_.same_feature_px;
  for (int i = 0; i < num_points; ++i) {
    const std::size_t u = std::size_t(i);
    s.feature_parent[u] = int16_t(i);
    if (!s.pose_point_inlier[u]) continue;
    const Eigen::Vector2d q_i = s.pose_points[u].z.head<2>();
    s.candidate_px[u] = projectToPixel(camera_, s.pose_points[u].P_world);
    for (int j = 0; j < i; ++j) {
      const std::size_t v = std::size_t(j);
      if (!s.pose_point_inlier[v]) continue;
      if ((q_i - s.pose_points[v].z.head<2>()).squaredNorm() > r2 &&
          (s.candidate_px[u] - s.candidate_px[v]).squaredNorm() > r2)
        continue;
      const int a = root(i), b = root(j);
      if (a != b) s.feature_parent[std::size_t(std::max(a, b))] = int16_t(std::min(a, b));
    }
  }
  // Each feature's information summed over its inliers in index order, one feature after the
  // other (no per-feature storage).
  int inliers = 0;
  for (int i = 0; i < num_points; ++i) {
    if (!s.pose_point_inlier[std::size_t(i)]) continue;
    s.feature_root[std::size_t(i)] = int16_t(root(i));
    s.by_feature[std::size_t(inliers++)] = int16_t(i);
  }
  std::sort(s.by_feature.begin(), s.by_feature.begin() + inliers, [&s](int16_t a, int16_t b) {
    const int16_t ra = s.feature_root[std::size_t(a)], rb = s.feature_root[std::size_t(b)];
    return ra != rb ? ra < rb : a < b;
  });
  double worst = 0;
  *feature = 0;
  auto consider = [&](const Matrix6d& information, int id) {
    const double leverage = groupLeverage(pose.covariance, information);
    if (leverage > worst) {
      worst = leverage;
      *feature = id;
    }
  };
  Matrix6d information = Matrix6d::Zero();
  for (int k = 0; k < inliers; ++k) {
    const std::size_t i = std::size_t(s.by_feature[std::size_t(k)]);
    information += poseInformation(camera_, pose.T_cam_world, s.pose_points[i], pose_options);
    const bool last = k + 1 == inliers || s.feature_root[std::size_t(s.by_feature[std::size_t(k + 1)])] != s.feature_root[i];
    if (!last) continue;
    consider(information, s.feature_root[i]);
    information.setZero();
  }
  for (int k = 0; k < num_lines; ++k) {
    if (s.pose_line_inlier[std::size_t(k)])
      information += poseInformation(camera_, pose.T_cam_world, s.pose_lines[std::size_t(k)], pose_options);
    if (k + 1 < num_lines && s.line_of_sample[std::size_t(k + 1)] == s.line_of_sample[std::size_t(k)]) continue;
    consider(information, -(int(s.line_of_sample[std::size_t(k)]) + 1));
    information.setZero();
  }
  return worst;
}

void LoopVerifier::dropFeature(int feature, int* num_points, int* num_lines) const {
  Scratch& s = *s_;
  if (feature >= 0) {
    // The inliers' roots as weakestFeature() stored them (moving observations would break the
    // parent links, so they are read before any observation moves).
    for (int i = 0; i < *num_points; ++i)
      s.keep[std::size_t(i)] = !s.pose_point_inlier[std::size_t(i)] || s.feature_root[std::size_t(i)] != feature;
    int n = 0;
    for (int i = 0; i < *num_points; ++i)
      if (s.keep[std::size_t(i)]) s.pose_points[std::size_t(n++)] = s.pose_points[std::size_t(i)];
    *num_points = n;
    return;
  }
  const int line = -feature - 1;
  int n = 0;
  for (int k = 0; k < *num_lines; ++k) {
    if (int(s.line_of_sample[std::size_t(k)]) == line) continue;
    s.pose_lines[std::size_t(n)] = s.pose_lines[std::size_t(k)];
    s.line_of_sample[std::size_t(n++)] = s.line_of_sample[std::size_t(k)];
  }
  *num_lines = n;
}

Matrix6d LoopVerifier::calibratedCovariance(const PoseResult& pose, const PoseOptimizerOptions& pose_options) const {
  if (!options_.calibrate_covariance) return pose.covariance;
  const UncertaintyOptions& u = options_.uncertainty;
  // Variance factor of the point residuals only: a line's N samples carry 1/N of a sample's
  // information each (options above), so their chi2 is not a unit-variance measurement's.
  InlierChi2Sums points = pose.inlier_chi2;
  points.chi2[0] = 0;
  points.count[0] = 0;
  const double variance_factor = u.use_variance_factor ? varianceFactor(points, 6.0, pose_options.chi2) : 1.0;
  Matrix6d covariance = variance_factor * u.loop_scale * pose.covariance;
  // Each image's rolling-shutter error: the query's directly, the candidate's through
  // Ad(T_query_candidate) (a left perturbation of the candidate's pose moves T_query_candidate by
  // -Ad(T_query_candidate) of it).
  const Matrix6d rolling_shutter = rollingShutterCovariance(u, options_.rolling_shutter_readout_s);
  const Matrix6d A = adjointSE3(pose.T_cam_world);
  covariance += rolling_shutter + A * rolling_shutter * A.transpose();
  return covariance;
}

LoopMeasurement LoopVerifier::verify(const LoopKeyframe& query, const LoopCandidate& candidate) {
  LoopMeasurement m;
  Scratch& s = *s_;
  // 1. Points. A query point whose two nearest candidate descriptors are too alike for the ratio
  // test (a copy of the same furniture, a repeated texture) enters with BOTH as hypotheses when
  // both are within the Hamming bound: the rigid RANSAC below tells them apart by geometry, where
  // the ratio test could only drop the point. The counts below are of query points.
  int n = 0;
  auto hypothesis = [&](std::size_t k, int j) {
    s.query_index[std::size_t(n)] = uint16_t(k);
    s.from[std::size_t(n)] = query.points[k].P_cam.cast<double>();
    s.to[std::size_t(n)] = candidate.P_cam[std::size_t(j)].cast<double>();
    s.candidate_octave[std::size_t(n)] = candidate.point_octave[std::size_t(j)];
    ++n;
  };
  // Below this bound the scan decides every match as the full one (ratioBound: best within the
  // threshold, the ratio test, and a second best within the threshold for the ambiguous pairs).
  const int bound = ratioBound(options_.hamming_threshold, options_.ratio);
  for (std::size_t k = 0; k < query.points.size(); ++k) {
    const NearestTwo nearest = nearestTwoBelow(query.point_descriptors[k], candidate.point_descriptors.data(),
                                               candidate.num_points, bound);
    if (nearest.best_index < 0 || nearest.best > options_.hamming_threshold) continue;
    const bool clear = passesRatio(nearest, options_.ratio);
    const bool ambiguous = !clear && options_.ambiguous_pairs && nearest.second <= options_.hamming_threshold;
    if (!clear && !ambiguous) continue;
    hypothesis(k, nearest.best_index);
    if (ambiguous) hypothesis(k, nearest.second_index);
    ++m.matches;
  }
  if (m.matches < options_.min_matches) return m;

  // 2. Rigid RANSAC: T_candidate_query maps query-camera points onto candidate-camera points.
  Eigen::Isometry3d T_cq = Eigen::Isometry3d::Identity();
  (void)rigidRansac(s.from.data(), s.to.data(), n, options_.ransac, s.ransac_scratch.data(), s.inlier.data(),
                    &T_cq);
  // One inlier per query point (its two hypotheses are adjacent; both fit only when the two
  // candidate points lie within the inlier threshold of each other).
  m.ransac_inliers = 0;
  for (int i = 0; i < n; ++i) {
    const std::size_t u = std::size_t(i);
    if (s.inlier[u] && i > 0 && s.inlier[u - 1] && s.query_index[u - 1] == s.query_index[u]) s.inlier[u] = false;
    m.ransac_inliers += s.inlier[u] ? 1 : 0;
  }
  if (m.ransac_inliers < options_.min_inliers) {
    m.rejection = LoopRejection::kFewInliers;
    return m;
  }
  if (double(m.ransac_inliers) < options_.min_inlier_ratio * double(m.matches)) {
    m.rejection = LoopRejection::kLowInlierRatio;
    return m;
  }

  // 3. Refinement: candidate camera = "world", query = the camera being posed. Each residual's
  // information is the inverse of the query observation's covariance plus the candidate point's,
  // carried through the projection at the RANSAC pose (options: propagate_candidate_noise).
  const Eigen::Isometry3d T_qc = T_cq.inverse();
  int num_points = 0;
  for (int i = 0; i < n; ++i) {
    if (!s.inlier[std::size_t(i)]) continue;
    const uint16_t k = s.query_index[std::size_t(i)];
    const LoopPoint& q = query.points[k];
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
    const Eigen::Vector3d X = T_qc * obs.P_world;
    const Eigen::Matrix3d S_X = candidateCovarianceInQuery(obs.P_world, s.candidate_octave[std::size_t(i)], T_qc);
    if (!(X.z() > kFactorMinDepth) || !(S_X.trace() > 0)) continue;
    if (obs.has_depth) {
      Eigen::Vector3d e;
      Eigen::Matrix3d J;
      stereoResidualAt(camera_, X, obs.z, &e, &J);
      obs.information = (obs.information.inverse() + J * S_X * J.transpose()).inverse();
    } else {
      Eigen::Vector2d e;
      Matrix23d J;
      monoResidualAt(camera_, X, obs.z.head<2>(), &e, &J);
      obs.information.topLeftCorner<2, 2>() =
          (obs.information.topLeftCorner<2, 2>().inverse() + J * S_X * J.transpose()).inverse();
    }
  }
  int num_lines = 0;
  if (options_.use_lines) {
    for (std::size_t k = 0; k < query.lines.size(); ++k) {
      const int j =
          bestRatioMatch(query.line_descriptors[k], candidate.line_descriptors.data(), candidate.num_lines,
                    options_.line_hamming_threshold, options_.line_ratio);
      if (j < 0) continue;
      const std::size_t first = candidate.first_sample[std::size_t(j)];
      const std::size_t count = candidate.num_samples[std::size_t(j)];
      const LoopLine& q = query.lines[k];
      if (!lineAgrees(q, &candidate.samples_cam[first], count, T_qc)) continue;
      const uint8_t line_index = uint8_t(m.line_matches++);
      const double per_line = options_.line_information_per_line ? double(count) : 1.0;
      const double query_variance = 1.0 / lineSampleInformation(noise_, q.octave);
      for (std::size_t smp = 0; smp < count; ++smp) {
        s.line_of_sample[std::size_t(num_lines)] = line_index;
        PoseLineObservation& obs = s.pose_lines[std::size_t(num_lines++)];
        obs.P_world = candidate.samples_cam[first + smp].cast<double>();
        obs.line = q.l.cast<double>();
        double variance = query_variance;
        const Eigen::Vector3d X = T_qc * obs.P_world;
        if (X.z() > kFactorMinDepth) {
          double e = 0;
          Eigen::RowVector3d J;
          lineResidualAt(camera_, X, obs.line, &e, &J);
          variance += J * candidateCovarianceInQuery(obs.P_world, candidate.line_octave[std::size_t(j)], T_qc) *
                      J.transpose();
        }
        obs.information = 1.0 / (variance * per_line);
      }
    }
  }
  PoseOptimizerOptions pose_options;
  auto refine = [&](const Eigen::Isometry3d& T_query_candidate) {
    return optimizePose(camera_, T_query_candidate, s.pose_points.data(), num_points, s.pose_lines.data(), num_lines,
                        pose_options, s.pose_point_inlier.data(), num_lines > 0 ? s.pose_line_inlier.data() : nullptr);
  };
  PoseResult pose = refine(T_qc);
  // 4. Reliability: no single feature may carry the pose (options: max_feature_leverage).
  for (;;) {
    m.refined_inliers = pose.num_point_inliers;
    m.line_inliers = pose.num_line_inliers;
    if (m.refined_inliers < options_.min_refined_inliers || !pose.covariance_valid) {
      m.rejection = LoopRejection::kRefinement;
      return m;
    }
    int feature = 0;
    m.max_leverage = weakestFeature(pose, num_points, num_lines, pose_options, &feature);
    if (m.max_leverage <= options_.max_feature_leverage) break;
    if (m.unreliable_features >= options_.max_unreliable_features) {
      m.rejection = LoopRejection::kUncertain;
      return m;
    }
    dropFeature(feature, &num_points, &num_lines);
    ++m.unreliable_features;
    pose = refine(pose.T_cam_world);
  }
  m.T_candidate_query = pose.T_cam_world.inverse();
  m.covariance = calibratedCovariance(pose, pose_options);
  m.rejection = LoopRejection::kNone;
  return m;
}

}  // namespace plumb::loop
