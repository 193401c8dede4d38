// LocalBundleAdjuster, outer loop: Levenberg-Marquardt step control, costs, outlier flags and
// the covariance of the optimised poses.
#include <algorithm>
#include <cmath>

#include "solver/dense_cholesky.h"
#include "solver/factors.h"
#include "solver/local_ba.h"
#include "solver/se3.h"
#include "solver/trust_region.h"

namespace plumb {

// chi2 of one observation at a given pose and point (false: behind the camera). Defined here, in
// the translation unit of its three callers and forced inline (GCC kept one out-of-line copy for
// the three call sites, a call and a switch per observation and candidate).
__attribute__((always_inline)) inline bool LocalBundleAdjuster::evaluateChi2(const Observation& obs, const Eigen::Isometry3d& T_cam_world,
                                          const Eigen::Vector3d& P_world, double* chi2) const {
  switch (obs.kind) {
    case ObservationKind::kStereoPoint: {
      Eigen::Vector3d e;
      if (!evaluateStereoPoint(camera_, T_cam_world, P_world, obs.z, &e, nullptr, nullptr)) return false;
      *chi2 = e.dot(obs.information * e);
      return true;
    }
    case ObservationKind::kMonoPoint: {
      Eigen::Vector2d e;
      if (!evaluateMonoPoint(camera_, T_cam_world, P_world, obs.z.head<2>(), &e, nullptr, nullptr)) return false;
      *chi2 = e.dot(obs.information.topLeftCorner<2, 2>() * e);
      return true;
    }
    case ObservationKind::kLineSample: {
      double e;
      if (!evaluateLineSample(camera_, T_cam_world, P_world, obs.z, &e, nullptr, nullptr)) return false;
      *chi2 = e * e * obs.information(0, 0);
      return true;
    }
  }
  return false;
}

// Robust cost at the candidate estimate over the observations valid at the linearisation point.
// *all_valid turns false when the candidate moves one of them behind its camera.
double LocalBundleAdjuster::candidateCost(const LocalBaOptions& options, bool* all_valid) const {
  const RobustKernel kernels[3] = {options.kernelFor(ObservationKind::kStereoPoint),
                                   options.kernelFor(ObservationKind::kMonoPoint),
                                   options.kernelFor(ObservationKind::kLineSample)};
  double cost = 0.0;
  *all_valid = true;
  for (int k = 0; k < num_observations_; ++k) {
    const Observation& obs = observations_[k];
    if (!obs.valid) continue;
    double chi2 = 0.0;
    if (!evaluateChi2(obs, keyframes_[obs.keyframe].T_candidate, landmarks_[obs.landmark].P_candidate, &chi2)) {
      *all_valid = false;
      return cost;
    }
    cost += 0.5 * robustCost(kernels[static_cast<int>(obs.kind)], chi2);
  }
  return cost;
}

double LocalBundleAdjuster::cost(const LocalBaOptions& options) const {
  double cost = 0.0;
  for (int k = 0; k < num_observations_; ++k) {
    const Observation& obs = observations_[k];
    double chi2 = 0.0;
    if (!obs.enabled ||
        !evaluateChi2(obs, keyframes_[obs.keyframe].T_cam_world, landmarks_[obs.landmark].P_world, &chi2))
      continue;
    cost += 0.5 * robustCost(options.kernelFor(obs.kind), chi2);
  }
  return cost;
}

void LocalBundleAdjuster::updateOutlierFlags(const LocalBaOptions& options, LocalBaSummary* summary) {
  summary->num_outliers = 0;
  for (int k = 0; k < num_observations_; ++k) {
    Observation& obs = observations_[k];
    if (!obs.enabled) {
      obs.outlier = false;
      continue;
    }
    const bool in_front =
        evaluateChi2(obs, keyframes_[obs.keyframe].T_cam_world, landmarks_[obs.landmark].P_world, &obs.chi2);
    obs.outlier = !in_front || obs.chi2 > options.chi2ThresholdFor(obs.kind);
    summary->num_outliers += obs.outlier ? 1 : 0;
  }
}

LocalBaSummary LocalBundleAdjuster::solve(const LocalBaOptions& options) {
  LocalBaSummary summary;
  covariance_valid_ = false;
  linearized_at_estimate_ = false;
  if (num_pose_variables_ == 0 && num_landmarks_ == 0) return summary;
  buildStructure();
  double cost = linearize(options);
  summary.initial_cost = cost;
  summary.status = LocalBaStatus::kMaxIterations;
  TrustRegion region(options.initial_trust_radius, options.max_trust_radius);
  bool relinearize = false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    if (relinearize) cost = linearize(options);
    relinearize = false;
    const double lambda = region.lambda();
    ++summary.iterations;
    bool step_ok = solveDamped(options, lambda);
    bool all_valid = false;
    double new_cost = cost;
    double predicted = 0.0;
    if (step_ok) {
      for (int i = 0; i < num_keyframes_; ++i) {
        Keyframe& kf = keyframes_[i];
        kf.T_candidate = kf.variable >= 0 ? applyLeftIncrement(kf.step, kf.T_cam_world) : kf.T_cam_world;
      }
      for (int j = 0; j < num_landmarks_; ++j) landmarks_[j].P_candidate = landmarks_[j].P_world + landmarks_[j].step;
      new_cost = candidateCost(options, &all_valid);
      predicted = modelCostReduction(lambda);
    }
    const double actual = cost - new_cost;
    const double step_quality = TrustRegion::stepQuality(actual, predicted);
    if (step_ok && all_valid && std::isfinite(new_cost) && step_quality > options.min_relative_decrease) {
      for (int i = 0; i < num_keyframes_; ++i) keyframes_[i].T_cam_world = keyframes_[i].T_candidate;
      for (int j = 0; j < num_landmarks_; ++j) landmarks_[j].P_world = landmarks_[j].P_candidate;
      region.stepAccepted(step_quality);
      ++summary.successful_steps;
      relinearize = true;
      const double relative_change = actual / std::max(cost, 1e-300);
      cost = new_cost;
      if (relative_change < options.function_tolerance) {
        summary.status = LocalBaStatus::kConverged;
        break;
      }
    } else {
      region.stepRejected();
    }
  }
  summary.final_cost = cost;
  summary.num_fixed_landmarks = num_fixed_landmarks_;
  linearized_at_estimate_ = !relinearize;
  updateOutlierFlags(options, &summary);
  return summary;
}

bool LocalBundleAdjuster::computeStep(const LocalBaOptions& options, double lambda) {
  buildStructure();
  linearize(options);
  linearized_at_estimate_ = true;
  return solveDamped(options, lambda);
}

bool LocalBundleAdjuster::computeCovariance(const LocalBaOptions& options, const InformationScales& scales) {
  covariance_valid_ = false;
  buildStructure();
  const bool unit_scales = scales.pixel == 1.0 && scales.depth == 1.0 && scales.line == 1.0;
  // When solve() ended at its last linearisation point (its last step was rejected, or it ran no
  // step) and the covariance weighs the residuals as solve() did, the stored blocks are this
  // linearisation. Otherwise (the estimate moved, or variance components weigh the residual kinds
  // differently): linearise again. Either way solve()'s outlier flags stay as they are.
  if (!(linearized_at_estimate_ && unit_scales)) {
    information_scales_ = scales;
    linearize(options);
    information_scales_ = InformationScales();
    linearized_at_estimate_ = unit_scales;
  }
  // lambda = 0: the undamped reduced system S = H_A - H_B H_C^-1 H_B^T, factorised in place.
  // (The steps are not needed: no back-substitution, poseStep()/landmarkStep() keep their values.)
  if (!solveDamped(options, 0.0, /*back_substitute=*/false)) return false;
  const Eigen::Index dim = 6 * static_cast<Eigen::Index>(num_pose_variables_);
  choleskyInverse(S_.topLeftCorner(dim, dim), covariance_.topLeftCorner(dim, dim));
  if (!covariance_.topLeftCorner(dim, dim).allFinite()) return false;
  // A direction the observations do not fix survives the factorisation as a pivot of rounding
  // size and either sign: refuse it when a variable's marginal information 1 / C_kk is not well
  // above the rounding error of the terms it was computed from (its own information H_kk).
  for (int v = 0; v < num_pose_variables_; ++v) {
    const Matrix6d& H = keyframes_[variable_keyframe_[v]].H_pose;
    for (int d = 0; d < 6; ++d) {
      const Eigen::Index k = 6 * v + d;
      const double inflation = covariance_(k, k) * H(d, d);
      if (!(inflation <= options.covariance_max_variance_inflation)) return false;
    }
  }
  covariance_valid_ = true;
  return true;
}

}  // namespace plumb
