#include "pipeline/loop/loop_verifier.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "pipeline/frontend/descriptor_match.h"
#include "solver/factors.h"
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

struct LoopVerifier::Scratch {
  std::array<uint16_t, kMaxLoopPoints> query_index{};  // per match
  std::array<Eigen::Vector3d, kMaxLoopPoints> from{};  // query camera
  std::array<Eigen::Vector3d, kMaxLoopPoints> to{};    // candidate camera
  std::array<int8_t, kMaxLoopPoints> candidate_octave{};
  std::array<bool, kMaxLoopPoints> ransac_scratch{};
  std::array<bool, kMaxLoopPoints> inlier{};
  std::array<PosePointObservation, kMaxLoopPoints> pose_points{};
  std::array<bool, kMaxLoopPoints> pose_point_inlier{};
  std::array<PoseLineObservation, kMaxLoopLines * kMaxLineSamples> pose_lines{};
  std::array<bool, kMaxLoopLines * kMaxLineSamples> pose_line_inlier{};
};

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
  // 1. Points.
  int n = 0;
  for (std::size_t k = 0; k < query.points.size(); ++k) {
    const int j = bestRatioMatch(query.point_descriptors[k], candidate.point_descriptors.data(),
                            candidate.num_points, options_.hamming_threshold, options_.ratio);
    if (j < 0) continue;
    s.query_index[std::size_t(n)] = uint16_t(k);
    s.from[std::size_t(n)] = query.points[k].P_cam.cast<double>();
    s.to[std::size_t(n)] = candidate.P_cam[std::size_t(j)].cast<double>();
    s.candidate_octave[std::size_t(n)] = candidate.point_octave[std::size_t(j)];
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
      ++m.line_matches;
      const double per_line = options_.line_information_per_line ? double(count) : 1.0;
      const double query_variance = 1.0 / lineSampleInformation(noise_, q.octave);
      for (std::size_t smp = 0; smp < count; ++smp) {
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
  m.covariance = calibratedCovariance(pose, pose_options);
  m.rejection = LoopRejection::kNone;
  return m;
}

}  // namespace plumb::loop
