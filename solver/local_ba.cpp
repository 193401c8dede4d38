#include "solver/local_ba.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "solver/dense_cholesky.h"
#include "solver/factors.h"
#include "solver/se3.h"

namespace plumb {
namespace {

// LM damping uses clamp(diag(H)) like Ceres, so zero-information directions still get damped.
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;

RobustKernel kernelFor(const LocalBaOptions& options, ObservationKind kind) {
  switch (kind) {
    case ObservationKind::kStereoPoint:
      return {options.kernel, options.kernel_delta_stereo};
    case ObservationKind::kMonoPoint:
      return {options.kernel, options.kernel_delta_mono};
    case ObservationKind::kLineSample:
      break;
  }
  return {options.kernel, options.kernel_delta_line};
}

double chi2Threshold(const LocalBaOptions& options, ObservationKind kind) {
  switch (kind) {
    case ObservationKind::kStereoPoint:
      return options.chi2_stereo;
    case ObservationKind::kMonoPoint:
      return options.chi2_mono;
    case ObservationKind::kLineSample:
      break;
  }
  return options.chi2_line;
}

// Damping added to a diagonal entry of H.
inline double damping(double lambda, double diagonal) {
  return lambda * std::clamp(diagonal, kMinDiagonal, kMaxDiagonal);
}

// One whitened-and-weighted observation of R rows, folded into the landmark / pose blocks.
struct BlockSinks {
  Eigen::Matrix3d* H_point;
  Eigen::Vector3d* g_point;
  Matrix6d* H_pose;  // null for a fixed keyframe
  Vector6d* g_pose;
  Matrix63d* W;
};

template <int R>
void accumulate(const Eigen::Matrix<double, R, 6>& J_pose, const Eigen::Matrix<double, R, 3>& J_point,
                const Eigen::Matrix<double, R, 1>& e, const Eigen::Matrix<double, R, R>& weighted_information,
                const BlockSinks& out) {
  const Eigen::Matrix<double, 3, R> Jl_t_omega = J_point.transpose() * weighted_information;
  out.H_point->noalias() += Jl_t_omega * J_point;
  out.g_point->noalias() += Jl_t_omega * e;
  if (out.H_pose == nullptr) return;
  const Eigen::Matrix<double, 6, R> Jp_t_omega = J_pose.transpose() * weighted_information;
  out.H_pose->noalias() += Jp_t_omega * J_pose;
  out.g_pose->noalias() += Jp_t_omega * e;
  out.W->noalias() = Jp_t_omega * J_point;
}

// (Pseudo-)inverse of a 3x3 landmark block. Well-conditioned blocks take the Cholesky path. A
// rank-deficient block is inverted on its range only: a line-guidance point seen on exact lines
// can slide along its 3D line without changing any residual, so that direction is in the null
// space of both H_ll and H_lp and the pseudo-inverse gives the exact Schur complement (and a zero
// step along the line). Returns false for a zero or non-finite block: the landmark is then held
// fixed (its observations still constrain the poses through H_pp).
bool invertLandmarkBlock(const Eigen::Matrix3d& H, double singular_threshold, Eigen::Matrix3d* H_inv) {
  if (!H.allFinite()) return false;
  const Eigen::LLT<Eigen::Matrix3d> llt(H);
  const double max_diagonal = H.diagonal().maxCoeff();
  if (llt.info() == Eigen::Success && max_diagonal > 0.0) {
    const double min_pivot = llt.matrixLLT().diagonal().minCoeff();
    if (min_pivot * min_pivot > 1e-8 * max_diagonal) {  // condition well below 1e8: safe
      *H_inv = llt.solve(Eigen::Matrix3d::Identity());
      return true;
    }
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(H);
  const Eigen::Vector3d& values = eigen.eigenvalues();  // ascending
  if (!(values(2) > 0.0)) return false;
  H_inv->setZero();
  for (int d = 0; d < 3; ++d) {
    if (values(d) <= singular_threshold * values(2)) continue;
    const Eigen::Vector3d u = eigen.eigenvectors().col(d);
    H_inv->noalias() += (u / values(d)) * u.transpose();
  }
  return true;
}

}  // namespace

const char* toString(LocalBaStatus status) {
  switch (status) {
    case LocalBaStatus::kConverged:
      return "converged";
    case LocalBaStatus::kMaxIterations:
      return "max iterations";
    case LocalBaStatus::kNoVariables:
      return "no variables";
    case LocalBaStatus::kLinearSolverFailed:
      return "reduced camera system not positive definite";
  }
  return "unknown";
}

void LocalBundleAdjuster::reserve(int max_keyframes, int max_landmarks, int max_observations) {
  keyframes_.resize(std::max(max_keyframes, 0));
  landmarks_.resize(std::max(max_landmarks, 0));
  observations_.resize(std::max(max_observations, 0));
  observation_order_.resize(observations_.size());
  landmark_scratch_.resize(observations_.size());
  variable_keyframe_.resize(keyframes_.size());
  const Eigen::Index max_dim = 6 * static_cast<Eigen::Index>(keyframes_.size());
  S_.setZero(max_dim, max_dim);
  rhs_.setZero(max_dim);
  covariance_.setZero(max_dim, max_dim);
  clear();
}

void LocalBundleAdjuster::clear() {
  num_keyframes_ = 0;
  num_landmarks_ = 0;
  num_observations_ = 0;
  num_pose_variables_ = 0;
  num_fixed_landmarks_ = 0;
  covariance_valid_ = false;
}

int LocalBundleAdjuster::addKeyframe(const Eigen::Isometry3d& T_cam_world, bool fixed) {
  if (num_keyframes_ >= static_cast<int>(keyframes_.size()) || !T_cam_world.matrix().allFinite()) return -1;
  Keyframe& kf = keyframes_[num_keyframes_];
  kf.T_cam_world = T_cam_world;
  kf.step.setZero();
  kf.variable = fixed ? -1 : num_pose_variables_;
  if (!fixed) variable_keyframe_[num_pose_variables_++] = num_keyframes_;
  covariance_valid_ = false;
  return num_keyframes_++;
}

int LocalBundleAdjuster::addLandmark(const Eigen::Vector3d& P_world) {
  if (num_landmarks_ >= static_cast<int>(landmarks_.size()) || !P_world.allFinite()) return -1;
  Landmark& lm = landmarks_[num_landmarks_];
  lm.P_world = P_world;
  lm.step.setZero();
  lm.eliminated = false;
  return num_landmarks_++;
}

int LocalBundleAdjuster::addObservation(int keyframe, int landmark, ObservationKind kind,
                                        const Eigen::Vector3d& z, const Eigen::Matrix3d& information) {
  if (num_observations_ >= static_cast<int>(observations_.size())) return -1;
  if (keyframe < 0 || keyframe >= num_keyframes_ || landmark < 0 || landmark >= num_landmarks_) return -1;
  if (!z.allFinite() || !information.allFinite()) return -1;  // would poison the whole solve
  Observation& obs = observations_[num_observations_];
  obs.keyframe = keyframe;
  obs.landmark = landmark;
  obs.kind = kind;
  obs.z = z;
  obs.information = information;
  obs.enabled = true;
  obs.valid = false;
  obs.outlier = false;
  obs.chi2 = 0.0;
  return num_observations_++;
}

int LocalBundleAdjuster::addStereoPointObservation(int keyframe, int landmark, const Eigen::Vector3d& z_uvr,
                                                   const Eigen::Matrix3d& information) {
  return addObservation(keyframe, landmark, ObservationKind::kStereoPoint, z_uvr, information);
}

int LocalBundleAdjuster::addMonoPointObservation(int keyframe, int landmark, const Eigen::Vector2d& z_uv,
                                                 const Eigen::Matrix2d& information) {
  Eigen::Matrix3d info3 = Eigen::Matrix3d::Zero();
  info3.topLeftCorner<2, 2>() = information;
  return addObservation(keyframe, landmark, ObservationKind::kMonoPoint, Eigen::Vector3d(z_uv.x(), z_uv.y(), 0.0),
                        info3);
}

int LocalBundleAdjuster::addLineObservation(int keyframe, int landmark, const Eigen::Vector3d& line,
                                            double information) {
  Eigen::Matrix3d info3 = Eigen::Matrix3d::Zero();
  info3(0, 0) = information;
  return addObservation(keyframe, landmark, ObservationKind::kLineSample, line, info3);
}

void LocalBundleAdjuster::setObservationEnabled(int observation, bool enabled) {
  if (observation >= 0 && observation < num_observations_) observations_[observation].enabled = enabled;
}

// Groups observation indices by landmark (counting sort into the reserved order array).
void LocalBundleAdjuster::buildStructure() {
  for (int j = 0; j < num_landmarks_; ++j) landmarks_[j].num_observations = 0;
  for (int k = 0; k < num_observations_; ++k) ++landmarks_[observations_[k].landmark].num_observations;
  int offset = 0;
  for (int j = 0; j < num_landmarks_; ++j) {
    landmarks_[j].first_observation = offset;
    offset += landmarks_[j].num_observations;
    landmarks_[j].num_observations = 0;
  }
  for (int k = 0; k < num_observations_; ++k) {
    Landmark& lm = landmarks_[observations_[k].landmark];
    observation_order_[lm.first_observation + lm.num_observations++] = k;
  }
}

bool LocalBundleAdjuster::evaluateChi2(const Observation& obs, const Eigen::Isometry3d& T_cam_world,
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

double LocalBundleAdjuster::linearize(const LocalBaOptions& options) {
  for (int v = 0; v < num_pose_variables_; ++v) {
    Keyframe& kf = keyframes_[variable_keyframe_[v]];
    kf.H_pose.setZero();
    kf.g_pose.setZero();
  }
  double cost = 0.0;
  for (int j = 0; j < num_landmarks_; ++j) {
    Landmark& lm = landmarks_[j];
    lm.H_point.setZero();
    lm.g_point.setZero();
    for (int n = 0; n < lm.num_observations; ++n) {
      Observation& obs = observations_[observation_order_[lm.first_observation + n]];
      obs.valid = false;
      if (!obs.enabled) continue;
      Keyframe& kf = keyframes_[obs.keyframe];
      const bool free_pose = kf.variable >= 0;
      const BlockSinks sinks{&lm.H_point, &lm.g_point, free_pose ? &kf.H_pose : nullptr, &kf.g_pose, &obs.W};
      const RobustKernel kernel = kernelFor(options, obs.kind);
      switch (obs.kind) {
        case ObservationKind::kStereoPoint: {
          Eigen::Vector3d e;
          Matrix36d J_pose;
          Eigen::Matrix3d J_point;
          if (!evaluateStereoPoint(camera_, kf.T_cam_world, lm.P_world, obs.z, &e, &J_pose, &J_point)) break;
          obs.chi2 = e.dot(obs.information * e);
          const RobustKernelValue k = evaluateKernel(kernel, obs.chi2);
          accumulate<3>(J_pose, J_point, e, k.rho1 * obs.information, sinks);
          cost += 0.5 * k.rho;
          obs.valid = true;
          break;
        }
        case ObservationKind::kMonoPoint: {
          Eigen::Vector2d e;
          Matrix26d J_pose;
          Matrix23d J_point;
          if (!evaluateMonoPoint(camera_, kf.T_cam_world, lm.P_world, obs.z.head<2>(), &e, &J_pose, &J_point))
            break;
          const Eigen::Matrix2d omega = obs.information.topLeftCorner<2, 2>();
          obs.chi2 = e.dot(omega * e);
          const RobustKernelValue k = evaluateKernel(kernel, obs.chi2);
          accumulate<2>(J_pose, J_point, e, k.rho1 * omega, sinks);
          cost += 0.5 * k.rho;
          obs.valid = true;
          break;
        }
        case ObservationKind::kLineSample: {
          Eigen::Matrix<double, 1, 1> e;
          RowVector6d J_pose;
          Eigen::RowVector3d J_point;
          if (!evaluateLineSample(camera_, kf.T_cam_world, lm.P_world, obs.z, &e(0), &J_pose, &J_point)) break;
          obs.chi2 = e(0) * e(0) * obs.information(0, 0);
          const RobustKernelValue k = evaluateKernel(kernel, obs.chi2);
          const Eigen::Matrix<double, 1, 1> weighted_information(k.rho1 * obs.information(0, 0));
          accumulate<1>(J_pose, J_point, e, weighted_information, sinks);
          cost += 0.5 * k.rho;
          obs.valid = true;
          break;
        }
      }
      obs.outlier = !obs.valid;
    }
  }
  return cost;
}

// Eliminates the landmarks from the damped normal equations and solves for all steps.
bool LocalBundleAdjuster::solveDamped(const LocalBaOptions& options, double lambda) {
  const Eigen::Index dim = 6 * static_cast<Eigen::Index>(num_pose_variables_);
  auto S = S_.topLeftCorner(dim, dim);
  auto rhs = rhs_.head(dim);
  S.setZero();
  for (int v = 0; v < num_pose_variables_; ++v) {
    const Keyframe& kf = keyframes_[variable_keyframe_[v]];
    Matrix6d H_damped = kf.H_pose;
    for (int d = 0; d < 6; ++d) H_damped(d, d) += damping(lambda, kf.H_pose(d, d));
    S.block<6, 6>(6 * v, 6 * v) = H_damped;
    rhs.segment<6>(6 * v) = -kf.g_pose;
  }

  num_fixed_landmarks_ = 0;
  for (int j = 0; j < num_landmarks_; ++j) {
    Landmark& lm = landmarks_[j];
    Eigen::Matrix3d H_damped = lm.H_point;
    for (int d = 0; d < 3; ++d) H_damped(d, d) += damping(lambda, lm.H_point(d, d));
    lm.eliminated = invertLandmarkBlock(H_damped, options.landmark_singular_threshold, &lm.H_point_inv);
    if (!lm.eliminated) {
      ++num_fixed_landmarks_;
      continue;
    }
    // Gather the observations in free keyframes (contiguous ids), forming V = W H_ll^-1 and the
    // reduced right-hand side on the way.
    const int* order = &observation_order_[lm.first_observation];
    int* free_obs = landmark_scratch_.data();
    int num_free = 0;
    for (int a = 0; a < lm.num_observations; ++a) {
      Observation& obs = observations_[order[a]];
      const int v = keyframes_[obs.keyframe].variable;
      if (!obs.valid || v < 0) continue;
      obs.V.noalias() = obs.W * lm.H_point_inv;
      rhs.segment<6>(6 * v).noalias() += obs.V * lm.g_point;
      free_obs[num_free++] = order[a];
    }
    // S_ab -= V_a W_b^T for every unordered pair sharing this landmark, written into the lower
    // block triangle (row block >= column block), which is all the Cholesky reads.
    for (int a = 0; a < num_free; ++a) {
      const Observation& obs_a = observations_[free_obs[a]];
      const int v_a = keyframes_[obs_a.keyframe].variable;
      S.block<6, 6>(6 * v_a, 6 * v_a).noalias() -= obs_a.V * obs_a.W.transpose();
      for (int b = a + 1; b < num_free; ++b) {
        const Observation& obs_b = observations_[free_obs[b]];
        const int v_b = keyframes_[obs_b.keyframe].variable;
        if (v_b > v_a) {
          S.block<6, 6>(6 * v_b, 6 * v_a).noalias() -= obs_b.V * obs_a.W.transpose();
        } else if (v_b < v_a) {
          S.block<6, 6>(6 * v_a, 6 * v_b).noalias() -= obs_a.V * obs_b.W.transpose();
        } else {  // two observations in one keyframe: both cross terms land on its diagonal block
          S.block<6, 6>(6 * v_a, 6 * v_a).noalias() -= obs_a.V * obs_b.W.transpose();
          S.block<6, 6>(6 * v_a, 6 * v_a).noalias() -= obs_b.V * obs_a.W.transpose();
        }
      }
    }
  }

  if (dim > 0) {
    if (!choleskyInPlace(S)) return false;
    choleskySolveInPlace(S, rhs);
    if (!rhs.allFinite()) return false;
  }
  for (int i = 0; i < num_keyframes_; ++i) {
    Keyframe& kf = keyframes_[i];
    kf.step = kf.variable >= 0 ? Vector6d(rhs.segment<6>(6 * kf.variable)) : Vector6d::Zero();
  }
  // Back-substitution: dx_l = -H_ll^-1 (g_l + sum_i W_i^T dx_p_i).
  for (int j = 0; j < num_landmarks_; ++j) {
    Landmark& lm = landmarks_[j];
    if (!lm.eliminated) {
      lm.step.setZero();
      continue;
    }
    Eigen::Vector3d b = lm.g_point;
    const int* order = &observation_order_[lm.first_observation];
    for (int a = 0; a < lm.num_observations; ++a) {
      const Observation& obs = observations_[order[a]];
      const Keyframe& kf = keyframes_[obs.keyframe];
      if (obs.valid && kf.variable >= 0) b.noalias() += obs.W.transpose() * kf.step;
    }
    lm.step.noalias() = -lm.H_point_inv * b;
  }
  return true;
}

// Predicted decrease of the quadratic model for the step that solved (H + D) dx = -g:
// -(g^T dx + 0.5 dx^T H dx) = 0.5 (dx^T D dx - g^T dx).
double LocalBundleAdjuster::modelCostReduction(double lambda) const {
  double twice = 0.0;
  for (int v = 0; v < num_pose_variables_; ++v) {
    const Keyframe& kf = keyframes_[variable_keyframe_[v]];
    for (int d = 0; d < 6; ++d) {
      twice += damping(lambda, kf.H_pose(d, d)) * kf.step(d) * kf.step(d) - kf.g_pose(d) * kf.step(d);
    }
  }
  for (int j = 0; j < num_landmarks_; ++j) {
    const Landmark& lm = landmarks_[j];
    if (!lm.eliminated) continue;
    for (int d = 0; d < 3; ++d) {
      twice += damping(lambda, lm.H_point(d, d)) * lm.step(d) * lm.step(d) - lm.g_point(d) * lm.step(d);
    }
  }
  return 0.5 * twice;
}

// Robust cost at the candidate estimate over the observations valid at the linearisation point.
// *all_valid turns false when the candidate moves one of them behind its camera.
double LocalBundleAdjuster::candidateCost(const LocalBaOptions& options, bool* all_valid) const {
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
    cost += 0.5 * evaluateKernel(kernelFor(options, obs.kind), chi2).rho;
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
    cost += 0.5 * evaluateKernel(kernelFor(options, obs.kind), chi2).rho;
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
    obs.outlier = !in_front || obs.chi2 > chi2Threshold(options, obs.kind);
    summary->num_outliers += obs.outlier ? 1 : 0;
  }
}

LocalBaSummary LocalBundleAdjuster::solve(const LocalBaOptions& options) {
  LocalBaSummary summary;
  covariance_valid_ = false;
  if (num_pose_variables_ == 0 && num_landmarks_ == 0) return summary;
  buildStructure();
  double cost = linearize(options);
  summary.initial_cost = cost;
  summary.status = LocalBaStatus::kMaxIterations;
  double radius = options.initial_trust_radius;
  double decrease_factor = 2.0;
  bool relinearize = false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    if (relinearize) cost = linearize(options);
    relinearize = false;
    const double lambda = 1.0 / radius;
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
    const double step_quality = predicted > 0.0 ? actual / predicted : -1.0;
    if (step_ok && all_valid && std::isfinite(new_cost) && step_quality > options.min_relative_decrease) {
      for (int i = 0; i < num_keyframes_; ++i) keyframes_[i].T_cam_world = keyframes_[i].T_candidate;
      for (int j = 0; j < num_landmarks_; ++j) landmarks_[j].P_world = landmarks_[j].P_candidate;
      const double grow = 1.0 - std::pow(2.0 * step_quality - 1.0, 3);
      radius = std::min(options.max_trust_radius, radius / std::max(1.0 / 3.0, grow));
      decrease_factor = 2.0;
      ++summary.successful_steps;
      relinearize = true;
      const double relative_change = actual / std::max(cost, 1e-300);
      cost = new_cost;
      if (relative_change < options.function_tolerance) {
        summary.status = LocalBaStatus::kConverged;
        break;
      }
    } else {
      radius /= decrease_factor;
      decrease_factor *= 2.0;
    }
  }
  summary.final_cost = cost;
  summary.num_fixed_landmarks = num_fixed_landmarks_;
  updateOutlierFlags(options, &summary);
  return summary;
}

bool LocalBundleAdjuster::computeStep(const LocalBaOptions& options, double lambda) {
  buildStructure();
  linearize(options);
  return solveDamped(options, lambda);
}

bool LocalBundleAdjuster::computeCovariance(const LocalBaOptions& options) {
  covariance_valid_ = false;
  buildStructure();
  linearize(options);
  // lambda = 0: the undamped reduced system S = H_A - H_B H_C^-1 H_B^T, factorised in place.
  if (!solveDamped(options, 0.0)) return false;
  const Eigen::Index dim = 6 * static_cast<Eigen::Index>(num_pose_variables_);
  choleskyInverse(S_.topLeftCorner(dim, dim), covariance_.topLeftCorner(dim, dim));
  covariance_valid_ = covariance_.topLeftCorner(dim, dim).allFinite();
  return covariance_valid_;
}

Matrix6d LocalBundleAdjuster::covariance(int keyframe) const {
  const int v = keyframes_[keyframe].variable;
  if (!covariance_valid_ || v < 0) return Matrix6d::Zero();
  return covariance_.block<6, 6>(6 * v, 6 * v);
}

Eigen::Block<const Eigen::MatrixXd> LocalBundleAdjuster::fullCovariance() const {
  const Eigen::MatrixXd& covariance = covariance_;
  const Eigen::Index dim = covariance_valid_ ? 6 * static_cast<Eigen::Index>(num_pose_variables_) : 0;
  return covariance.topLeftCorner(dim, dim);
}

Vector6d LocalBundleAdjuster::poseStep(int keyframe) const { return keyframes_[keyframe].step; }

Eigen::Vector3d LocalBundleAdjuster::landmarkStep(int landmark) const { return landmarks_[landmark].step; }

}  // namespace plumb
