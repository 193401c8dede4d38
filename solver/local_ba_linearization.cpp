// LocalBundleAdjuster, numeric core: IRLS linearisation into the block buffers, elimination of the
// landmarks into the reduced camera system S, its Cholesky solve and the back-substitution
// (derivation in local_ba.h).
#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "solver/dense_cholesky.h"
#include "solver/factors.h"
#include "solver/finite_check.h"
#include "solver/local_ba.h"
#include "solver/noise_model.h"
#include "solver/point_space_blocks.h"
#include "solver/schur_kernels.h"

namespace plumb {
namespace {

// LM damping uses clamp(diag(H)) like Ceres, so zero-information directions still get damped.
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;

// Damping added to a diagonal entry of H.
inline double damping(double lambda, double diagonal) {
  return lambda * std::clamp(diagonal, kMinDiagonal, kMaxDiagonal);
}

// (Pseudo-)inverse of a 3x3 landmark block. Well-conditioned blocks take the Cholesky path. A
// rank-deficient block is inverted on its range only: a line-guidance point seen on exact lines
// can slide along its 3D line without changing any residual, so that direction is in the null
// space of both H_ll and H_lp and the pseudo-inverse gives the exact Schur complement (and a zero
// step along the line). Returns false for a zero or non-finite block: the landmark is then held
// fixed (its observations still constrain the poses through H_pp).
bool invertLandmarkBlock(const Eigen::Matrix3d& H, double singular_threshold, Eigen::Matrix3d* H_inv) {
  if (!allFiniteValues(H)) return false;  // H.allFinite(), in fewer instructions
  // Cholesky H = L L^T written out (Eigen's LLT of a 3x3 is a generic loop, ~3x the
  // instructions; this runs once per landmark per elimination), then H^-1 = L^-T L^-1.
  const double max_diagonal = H.diagonal().maxCoeff();
  const double d0 = H(0, 0);
  if (d0 > 0.0 && max_diagonal > 0.0) {
    const double l00 = std::sqrt(d0);
    const double l10 = H(1, 0) / l00, l20 = H(2, 0) / l00;
    const double d1 = H(1, 1) - l10 * l10;
    if (d1 > 0.0) {
      const double l11 = std::sqrt(d1);
      const double l21 = (H(2, 1) - l20 * l10) / l11;
      const double d2 = H(2, 2) - l20 * l20 - l21 * l21;
      // Smallest pivot^2 against the largest diagonal: condition well below 1e8 is safe.
      if (d2 > 0.0 && std::min({d0, d1, d2}) > 1e-8 * max_diagonal) {
        const double l22 = std::sqrt(d2);
        const double i00 = 1.0 / l00, i11 = 1.0 / l11, i22 = 1.0 / l22;  // L^-1, lower triangle
        const double i10 = -l10 * i00 * i11, i21 = -l21 * i11 * i22;
        const double i20 = -(l20 * i00 + l21 * i10) * i22;
        (*H_inv)(0, 0) = i00 * i00 + i10 * i10 + i20 * i20;
        (*H_inv)(1, 0) = (*H_inv)(0, 1) = i11 * i10 + i21 * i20;
        (*H_inv)(2, 0) = (*H_inv)(0, 2) = i22 * i20;
        (*H_inv)(1, 1) = i11 * i11 + i21 * i21;
        (*H_inv)(2, 1) = (*H_inv)(1, 2) = i22 * i21;
        (*H_inv)(2, 2) = i22 * i22;
        return true;
      }
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

// Per observation, in camera-point space (solver/point_space_blocks.h): the residual's 3x3
// M = J_cam^T (w Omega) J_cam and q = J_cam^T (w Omega) e give the landmark block R^T M R, the
// pose block A^T M A (summed per keyframe on the symmetric scalars) and W = A^T M R = [MR; [P]x MR].
double LocalBundleAdjuster::linearize(const LocalBaOptions& options) {
  for (int v = 0; v < num_pose_variables_; ++v) keyframes_[variable_keyframe_[v]].normal = PoseNormalAccumulator();
  double cost = 0.0;
  for (int j = 0; j < num_landmarks_; ++j) {
    Landmark& lm = landmarks_[j];
    lm.H_point.setZero();
    lm.g_point.setZero();
    for (int n = 0; n < lm.num_observations; ++n) {
      Observation& obs = observations_[observation_order_[lm.first_observation + n]];
      obs.valid = false;
      // The outlier flags are solve()'s result (updateOutlierFlags), not touched here: the
      // linearisation of computeCovariance() must leave them for the map stage's culling.
      if (!obs.enabled) continue;
      Keyframe& kf = keyframes_[obs.keyframe];
      const Eigen::Vector3d P_cam = kf.T_cam_world * lm.P_world;
      if (!(P_cam.z() > kFactorMinDepth)) continue;  // behind the camera: not linearised this time
      const RobustKernel kernel = options.kernelFor(obs.kind);
      Eigen::Matrix3d M;
      Eigen::Vector3d q;
      RobustKernelValue k;
      switch (obs.kind) {
        case ObservationKind::kStereoPoint: {
          Eigen::Vector3d e;
          Eigen::Matrix3d J_cam;
          stereoResidualAt(camera_, P_cam, obs.z, &e, &J_cam);
          const Eigen::Vector3d omega_e = obs.information * e;
          obs.chi2 = e.dot(omega_e);
          k = evaluateKernel(kernel, obs.chi2);
          if (information_scales_.pixel == 1.0 && information_scales_.depth == 1.0) {
            stereoPointSpaceBlocks(J_cam, obs.information, omega_e, k.rho1, &M, &q);
          } else {  // computeCovariance with variance components
            const Eigen::Matrix3d omega =
                scaleStereoInformation(obs.information, information_scales_.pixel, information_scales_.depth);
            stereoPointSpaceBlocks(J_cam, omega, omega * e, k.rho1, &M, &q);
          }
          break;
        }
        case ObservationKind::kMonoPoint: {
          Eigen::Vector2d e;
          Matrix23d J_cam;
          monoResidualAt(camera_, P_cam, obs.z.head<2>(), &e, &J_cam);
          const Eigen::Matrix2d omega = information_scales_.pixel * obs.information.topLeftCorner<2, 2>();
          obs.chi2 = e.dot(obs.information.topLeftCorner<2, 2>() * e);
          k = evaluateKernel(kernel, obs.chi2);
          pointSpaceBlocks<2>(J_cam, k.rho1 * omega, e, &M, &q);
          break;
        }
        case ObservationKind::kLineSample:
        default: {  // (the enum has no other value)
          // Rank one: with j = J_cam^T and c = w Omega, M = c j j^T, so every block is an outer
          // product: R^T M R = c r r^T (r = R^T j), W = A^T M R = u r^T (u = c A^T j =
          // c [j; P_cam x j]) and A^T M A = u (A^T j)^T, about half the work of the 3x3 forms.
          double e = 0.0;
          Eigen::RowVector3d J_cam;
          lineResidualAt(camera_, P_cam, obs.z, &e, &J_cam);
          obs.chi2 = e * e * obs.information(0, 0);
          k = evaluateKernel(kernel, obs.chi2);
          cost += 0.5 * k.rho;
          obs.valid = true;
          const double c = k.rho1 * obs.information(0, 0) * information_scales_.line;
          const Eigen::Vector3d j = J_cam.transpose();
          const Eigen::Vector3d r = kf.T_cam_world.linear().transpose() * j;
          const Eigen::Vector3d cr = c * r;
          lm.H_point.noalias() += cr * r.transpose();
          lm.g_point += e * cr;
          if (kf.variable < 0) continue;
          Vector6d A_t_j;
          A_t_j << j, P_cam.cross(j);
          const Vector6d u = c * A_t_j;
          kf.normal.addRankOne(u, A_t_j, e * u);
          for (int col = 0; col < 3; ++col) obs.W.col(col) = u * r(col);
          obs.V.col(0) = u;  // the factors of W for the elimination (Observation::V)
          obs.V.col(1).head<3>() = r;
          continue;
        }
      }
      cost += 0.5 * k.rho;
      obs.valid = true;
      const Eigen::Matrix3d R = kf.T_cam_world.linear();
      const Eigen::Matrix3d MR = M * R;
      lm.H_point.noalias() += R.transpose() * MR;
      lm.g_point.noalias() += R.transpose() * q;
      if (kf.variable < 0) continue;  // a fixed keyframe: residuals, no pose variable
      kf.normal.add(M, q, P_cam);
      obs.W.topRows<3>() = MR;
      for (int c = 0; c < 3; ++c) obs.W.block<3, 1>(3, c) = P_cam.cross(MR.col(c));
    }
  }
  for (int v = 0; v < num_pose_variables_; ++v) {
    Keyframe& kf = keyframes_[variable_keyframe_[v]];
    kf.normal.finish(&kf.H_pose, &kf.g_pose);
  }
  return cost;
}

// Eliminates the landmarks from the damped normal equations and solves for all steps.
bool LocalBundleAdjuster::solveDamped(const LocalBaOptions& options, double lambda, bool back_substitute) {
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
  double* const S_data = S.data();
  const Eigen::Index stride = S.outerStride();
  // 6x6 block (row_variable, col_variable) of S.
  auto block = [S_data, stride](int row_variable, int col_variable) {
    return S_data + 6 * (static_cast<Eigen::Index>(row_variable) + stride * col_variable);
  };
  // Consecutive landmarks seen only by line samples, by the same free keyframes (the samples of
  // one line, as the local mapper adds them) update the same blocks of S. Their updates are held
  // back as a run and then written block by block, the landmarks in order inside each block
  // (subtractScaledOuterRun): every entry of S gets the same subtractions in the same order as
  // landmark by landmark, but each block is loaded and stored once a run. The run's observations
  // are the first run_length * run_width entries of the scratch lists (landmark-major); a
  // landmark that writes S otherwise writes the run first.
  constexpr int kMaxRun = 32;
  int run_length = 0, run_width = 0;
  const int* run_var = landmark_scratch_.data();
  auto flush_run = [&]() {
    Observation* const* run_obs = landmark_scratch_obs_.data();
    const double** u = landmark_scratch_u_.data();
    for (int i = 0; i < run_length * run_width; ++i) u[i] = run_obs[i]->V.data();  // column 0: u
    double gamma[kMaxRun];
    for (int a = 0; a < run_width; ++a) {
      for (int l = 0; l < run_length; ++l) {
        const Observation& obs_a = *run_obs[l * run_width + a];
        const Eigen::Vector3d r_a = obs_a.V.col(1).head<3>();
        gamma[l] = r_a.dot(obs_a.V.col(2).head<3>());
      }
      subtractScaledOuterLowerRun(run_length, gamma, u, run_width, a, block(run_var[a], run_var[a]), stride);
      for (int b = a + 1; b < run_width; ++b) {
        for (int l = 0; l < run_length; ++l) {
          const Eigen::Vector3d r_a = run_obs[l * run_width + a]->V.col(1).head<3>();
          gamma[l] = r_a.dot(run_obs[l * run_width + b]->V.col(2).head<3>());  // r_a^T H^-1 r_b
        }
        subtractScaledOuterRun(run_length, gamma, u, run_width, b, a, block(run_var[b], run_var[a]), stride);
      }
    }
    run_length = 0;
  };
  for (int j = 0; j < num_landmarks_; ++j) {
    Landmark& lm = landmarks_[j];
    Eigen::Matrix3d H_damped = lm.H_point;
    for (int d = 0; d < 3; ++d) {
      lm.damping(d) = damping(lambda, lm.H_point(d, d));  // kept for modelCostReduction(lambda)
      H_damped(d, d) += lm.damping(d);
    }
    lm.eliminated = invertLandmarkBlock(H_damped, options.landmark_singular_threshold, &lm.H_point_inv);
    if (!lm.eliminated) {  // writes neither S nor rhs: a run goes on past it
      ++num_fixed_landmarks_;
      continue;
    }
    // Gather the observations in free keyframes with their pose variables, so that the pair loops
    // below read neither the observation order nor the keyframes again (after the pending run's).
    const int* order = &observation_order_[lm.first_observation];
    const int gathered_at = run_length * run_width;
    Observation** free_obs = landmark_scratch_obs_.data() + gathered_at;
    int* free_var = landmark_scratch_.data() + gathered_at;
    int num_free = 0;
    bool all_line_samples = true;
    bool increasing = true;  // distinct variables, each pair of observations its own block
    for (int a = 0; a < lm.num_observations; ++a) {
      Observation& obs = observations_[order[a]];
      const int v = keyframes_[obs.keyframe].variable;
      if (!obs.valid || v < 0) continue;
      all_line_samples = all_line_samples && obs.kind == ObservationKind::kLineSample;
      increasing = increasing && (num_free == 0 || v > free_var[num_free - 1]);
      free_obs[num_free] = &obs;
      free_var[num_free++] = v;
    }
    if (all_line_samples) {
      // W_a = u_a r_a^T, so V_a W_b^T = u_a (r_a^T H_ll^-1 r_b) u_b^T: a scaled outer product of
      // two 6-vectors (about half the instructions of the general product); V g = u (H_ll^-1 r)^T g.
      for (int a = 0; a < num_free; ++a) {
        Observation& obs = *free_obs[a];
        obs.V.col(2).head<3>().noalias() = lm.H_point_inv * obs.V.col(1).head<3>();
        rhs.segment<6>(6 * free_var[a]) += obs.V.col(2).head<3>().dot(lm.g_point) * obs.V.col(0);
      }
      if (num_free == 0) continue;
      bool continues = run_length > 0 && num_free == run_width;  // (a loop: std::equal calls memcmp)
      for (int a = 0; continues && a < num_free; ++a) continues = free_var[a] == run_var[a];
      if (continues) {
        if (++run_length == kMaxRun) flush_run();
        continue;
      }
      if (run_length > 0) flush_run();
      if (increasing) {  // starts a run: move its lists to the front
        std::copy(free_obs, free_obs + num_free, landmark_scratch_obs_.data());
        std::copy(free_var, free_var + num_free, landmark_scratch_.data());
        run_width = num_free;
        run_length = 1;
        continue;
      }
      for (int a = 0; a < num_free; ++a) {
        const Observation& obs_a = *free_obs[a];
        const int v_a = free_var[a];
        const double* u_a = obs_a.V.col(0).data();
        const Eigen::Vector3d r_a = obs_a.V.col(1).head<3>();
        subtractScaledOuterLower(r_a.dot(obs_a.V.col(2).head<3>()), u_a, u_a, block(v_a, v_a), stride);
        for (int b = a + 1; b < num_free; ++b) {
          const Observation& obs_b = *free_obs[b];
          const int v_b = free_var[b];
          const double gamma = r_a.dot(obs_b.V.col(2).head<3>());  // r_a^T H^-1 r_b, symmetric
          const double* u_b = obs_b.V.col(0).data();
          if (v_b > v_a) {
            subtractScaledOuter(gamma, u_b, u_a, block(v_b, v_a), stride);
          } else if (v_b < v_a) {
            subtractScaledOuter(gamma, u_a, u_b, block(v_a, v_b), stride);
          } else {
            subtractScaledOuter(gamma, u_a, u_b, block(v_a, v_a), stride);
            subtractScaledOuter(gamma, u_b, u_a, block(v_a, v_a), stride);
          }
        }
      }
      continue;
    }
    if (run_length > 0) flush_run();
    // V = W H_ll^-1 and the reduced right-hand side.
    for (int a = 0; a < num_free; ++a) {
      Observation& obs = *free_obs[a];
      formVAndRhs(obs.W, lm.H_point_inv, lm.g_point, &obs.V, rhs.data() + 6 * free_var[a]);
    }
    // S_ab -= V_a W_b^T for every unordered pair sharing this landmark, written into the lower
    // block triangle (row block >= column block), which is all the Cholesky reads.
    for (int a = 0; a < num_free; ++a) {
      const Observation& obs_a = *free_obs[a];
      const int v_a = free_var[a];
      subtractVWtLower(obs_a.V, obs_a.W, block(v_a, v_a), stride);
      for (int b = a + 1; b < num_free; ++b) {
        const Observation& obs_b = *free_obs[b];
        const int v_b = free_var[b];
        if (v_b > v_a) {
          subtractVWt(obs_b.V, obs_a.W, block(v_b, v_a), stride);
        } else if (v_b < v_a) {
          subtractVWt(obs_a.V, obs_b.W, block(v_a, v_b), stride);
        } else {  // two observations in one keyframe: both cross terms land on its diagonal block
          subtractVWt(obs_a.V, obs_b.W, block(v_a, v_a), stride);
          subtractVWt(obs_b.V, obs_a.W, block(v_a, v_a), stride);
        }
      }
    }
  }

  if (run_length > 0) flush_run();

  if (dim > 0) {
    if (!choleskyInPlace(S)) return false;
    choleskySolveInPlace(S, rhs);
    if (!rhs.allFinite()) return false;
  }
  if (!back_substitute) return true;  // computeCovariance: the factor of S is all it reads
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
    for (int d = 0; d < 3; ++d) {  // the damping of the solveDamped(lambda) that gave the step
      twice += lm.damping(d) * lm.step(d) * lm.step(d) - lm.g_point(d) * lm.step(d);
    }
  }
  return 0.5 * twice;
}


}  // namespace plumb
