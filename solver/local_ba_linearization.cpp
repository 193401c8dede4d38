// LocalBundleAdjuster, numeric core: IRLS linearisation into the block buffers, elimination of the
// landmarks into the reduced camera system S, its Cholesky solve and the back-substitution
// (derivation in local_ba.h).
#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "solver/dense_cholesky.h"
#include "solver/factors.h"
#include "solver/local_ba.h"

namespace plumb {
namespace {

// LM damping uses clamp(diag(H)) like Ceres, so zero-information directions still get damped.
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;

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
      const RobustKernel kernel = options.kernelFor(obs.kind);
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


}  // namespace plumb
