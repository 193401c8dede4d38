#include "solver/pose_optimizer.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include "solver/factors.h"
#include "solver/point_space_blocks.h"
#include "solver/se3.h"

namespace plumb {
namespace {

struct Kernels {
  RobustKernel stereo, mono, line;
};

struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  double cost = 0.0;
};

// Chi-square (s = e^T Omega e) of a point observation; false when behind the camera.
bool pointChi2(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
               const PosePointObservation& obs, double* chi2) {
  if (obs.has_depth) {
    Eigen::Vector3d e;
    if (!evaluateStereoPoint(camera, T_cam_world, obs.P_world, obs.z, &e, nullptr, nullptr)) return false;
    *chi2 = e.dot(obs.information * e);
  } else {
    Eigen::Vector2d e;
    if (!evaluateMonoPoint(camera, T_cam_world, obs.P_world, obs.z.head<2>(), &e, nullptr, nullptr))
      return false;
    *chi2 = e.dot(obs.information.topLeftCorner<2, 2>() * e);
  }
  return true;
}

bool lineChi2(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
              const PoseLineObservation& obs, double* chi2) {
  double e;
  if (!evaluateLineSample(camera, T_cam_world, obs.P_world, obs.line, &e, nullptr, nullptr)) return false;
  *chi2 = e * e * obs.information;
  return true;
}

// Robust cost 0.5 * sum rho(s) over the observations flagged (or all when flags are null).
double robustCost(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                  const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
                  int num_lines, const Kernels& kernels, const bool* point_inliers, const bool* line_inliers) {
  double cost = 0.0;
  double chi2 = 0.0;
  for (int i = 0; i < num_points; ++i) {
    if (point_inliers != nullptr && !point_inliers[i]) continue;
    if (!pointChi2(camera, T_cam_world, points[i], &chi2)) continue;
    cost += 0.5 * evaluateKernel(points[i].has_depth ? kernels.stereo : kernels.mono, chi2).rho;
  }
  for (int i = 0; i < num_lines; ++i) {
    if (line_inliers != nullptr && !line_inliers[i]) continue;
    if (!lineChi2(camera, T_cam_world, lines[i], &chi2)) continue;
    cost += 0.5 * evaluateKernel(kernels.line, chi2).rho;
  }
  return cost;
}

// IRLS normal equations of the inliers at T_cam_world; with H_map, also the information blocks
// scaled by each observation's map_share (summed, not inverted: the map-error term of the top).
NormalEquations linearize(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                          const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
                          int num_lines, const Kernels& kernels, const bool* point_inliers,
                          const bool* line_inliers, Matrix6d* H_map = nullptr) {
  NormalEquations ne;
  PoseNormalAccumulator accumulator, map_accumulator;
  for (int i = 0; i < num_points; ++i) {
    if (!point_inliers[i]) continue;
    const PosePointObservation& obs = points[i];
    const Eigen::Vector3d P_cam = T_cam_world * obs.P_world;
    if (!(P_cam.z() > kFactorMinDepth)) continue;
    Eigen::Matrix3d M;
    Eigen::Vector3d q;
    if (obs.has_depth) {
      Eigen::Vector3d e;
      Eigen::Matrix3d J_cam;
      stereoResidualAt(camera, P_cam, obs.z, &e, &J_cam);
      const Eigen::Vector3d omega_e = obs.information * e;
      double rho = 0.0, weight = 0.0;
      robustCostAndWeight(kernels.stereo, e.dot(omega_e), &rho, &weight);
      stereoPointSpaceBlocks(J_cam, obs.information, omega_e, weight, &M, &q);
      ne.cost += 0.5 * rho;
    } else {
      Eigen::Vector2d e;
      Matrix23d J_cam;
      monoResidualAt(camera, P_cam, obs.z.head<2>(), &e, &J_cam);
      const Eigen::Matrix2d omega = obs.information.topLeftCorner<2, 2>();
      double rho = 0.0, weight = 0.0;
      robustCostAndWeight(kernels.mono, e.dot(omega * e), &rho, &weight);
      pointSpaceBlocks<2>(J_cam, weight * omega, e, &M, &q);
      ne.cost += 0.5 * rho;
    }
    accumulator.add(M, q, P_cam);
    if (H_map != nullptr && obs.map_share > 0) map_accumulator.add(obs.map_share * M, Eigen::Vector3d::Zero(), P_cam);
  }
  for (int i = 0; i < num_lines; ++i) {
    if (!line_inliers[i]) continue;
    const PoseLineObservation& obs = lines[i];
    const Eigen::Vector3d P_cam = T_cam_world * obs.P_world;
    if (!(P_cam.z() > kFactorMinDepth)) continue;
    double e = 0.0;
    Eigen::RowVector3d J_cam;
    lineResidualAt(camera, P_cam, obs.line, &e, &J_cam);
    double rho = 0.0, weight = 0.0;
    robustCostAndWeight(kernels.line, e * e * obs.information, &rho, &weight);
    // Rank one: A^T M A = u (A^T j)^T with j = J_cam^T, u = w Omega A^T j.
    const Eigen::Vector3d j = J_cam.transpose();
    Vector6d A_t_j;
    A_t_j << j, P_cam.cross(j);
    const Vector6d u = (weight * obs.information) * A_t_j;
    accumulator.addRankOne(u, A_t_j, e * u);
    if (H_map != nullptr && obs.map_share > 0) map_accumulator.addRankOne(obs.map_share * u, A_t_j, Vector6d::Zero());
    ne.cost += 0.5 * rho;
  }
  accumulator.finish(&ne.H, &ne.g);
  if (H_map != nullptr) {
    Vector6d unused;
    map_accumulator.finish(H_map, &unused);
  }
  return ne;
}

// Re-classifies every observation and fills the inlier counts; returns how many flags changed.
int classify(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
              const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
              int num_lines, const PoseOptimizerOptions& options, bool* point_inliers, bool* line_inliers,
              PoseResult* result) {
  result->num_point_inliers = 0;
  result->num_line_inliers = 0;
  result->inlier_chi2 = InlierChi2Sums{};
  int changed = 0;
  double chi2 = 0.0;
  for (int i = 0; i < num_points; ++i) {
    const double threshold = points[i].has_depth ? options.chi2.stereo : options.chi2.mono;
    const bool inlier = pointChi2(camera, T_cam_world, points[i], &chi2) && chi2 <= threshold;
    changed += inlier != point_inliers[i] ? 1 : 0;
    point_inliers[i] = inlier;
    result->num_point_inliers += inlier ? 1 : 0;
    if (inlier) result->inlier_chi2.add(points[i].has_depth ? 3 : 2, chi2);
  }
  for (int i = 0; i < num_lines; ++i) {
    const bool inlier = lineChi2(camera, T_cam_world, lines[i], &chi2) && chi2 <= options.chi2.line;
    changed += inlier != line_inliers[i] ? 1 : 0;
    line_inliers[i] = inlier;
    result->num_line_inliers += inlier ? 1 : 0;
    if (inlier) result->inlier_chi2.add(1, chi2);
  }
  return changed;
}

// The rotation nearest to `linear` in the Frobenius norm (U V^T of its SVD, reflection removed).
// Poses composed over many frames (velocity * last pose, keyframe * relative pose) drift off SO(3)
// by ~1e-5; left increments cannot remove that shear, so without this projection the optimum
// would depend on the start's shear, i.e. the result would lean towards the start.
Eigen::Matrix3d nearestRotation(const Eigen::Matrix3d& linear) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  if ((U * svd.matrixV().transpose()).determinant() < 0.0) U.col(2) = -U.col(2);
  return U * svd.matrixV().transpose();
}

}  // namespace

PoseResult optimizePose(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world_initial,
                        const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
                        int num_lines, const PoseOptimizerOptions& options, bool* point_inliers,
                        bool* line_inliers) {
  const Kernels kernels{{options.kernel, options.kernel_delta_stereo},
                        {options.kernel, options.kernel_delta_mono},
                        {options.kernel, options.kernel_delta_line}};
  PoseResult result;
  result.T_cam_world = T_cam_world_initial;
  result.T_cam_world.linear() = nearestRotation(T_cam_world_initial.linear());
  for (int i = 0; i < num_points; ++i) point_inliers[i] = true;
  for (int i = 0; i < num_lines; ++i) line_inliers[i] = true;

  for (int round = 0; round < options.rounds; ++round) {
    double lambda = options.initial_lambda;
    for (int it = 0; it < options.iterations_per_round; ++it) {
      const NormalEquations ne = linearize(camera, result.T_cam_world, points, num_points, lines, num_lines,
                                           kernels, point_inliers, line_inliers);
      // The first linearisation sees every observation at the initial pose: that is the initial cost.
      if (result.iterations == 0 && round == 0 && it == 0) result.initial_cost = ne.cost;
      Matrix6d H_damped = ne.H;
      if (options.levenberg_marquardt) H_damped.diagonal() += lambda * ne.H.diagonal();
      const Eigen::LDLT<Matrix6d> ldlt(H_damped);
      if (ldlt.info() != Eigen::Success) break;
      const Vector6d delta = -ldlt.solve(ne.g);
      if (!delta.allFinite()) break;
      ++result.iterations;
      const Eigen::Isometry3d T_candidate = applyLeftIncrement(delta, result.T_cam_world);
      if (options.levenberg_marquardt) {
        const double candidate_cost = robustCost(camera, T_candidate, points, num_points, lines, num_lines,
                                                 kernels, point_inliers, line_inliers);
        if (!(candidate_cost < ne.cost)) {
          lambda *= 10.0;
          continue;
        }
        lambda = std::max(lambda * 0.1, 1e-12);
      }
      result.T_cam_world = T_candidate;
      if (delta.norm() < options.step_tolerance) break;
    }
    const int changed = classify(camera, result.T_cam_world, points, num_points, lines, num_lines, options,
                                 point_inliers, line_inliers, &result);
    // Same inlier set as this round optimised: further rounds would repeat it exactly.
    if (changed == 0) break;
  }

  if (!options.compute_covariance) return result;
  Matrix6d H_map;
  const NormalEquations ne = linearize(camera, result.T_cam_world, points, num_points, lines, num_lines,
                                       kernels, point_inliers, line_inliers, &H_map);
  result.final_cost = ne.cost;
  const Eigen::LLT<Matrix6d> llt(ne.H);
  if (llt.info() == Eigen::Success) {
    result.covariance = llt.solve(Matrix6d::Identity());
    result.map_covariance = result.covariance * H_map * result.covariance;
    result.covariance_valid = result.covariance.allFinite() && result.map_covariance.allFinite();
  }
  return result;
}

}  // namespace plumb
