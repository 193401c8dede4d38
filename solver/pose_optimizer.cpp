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

// One point observation's IRLS blocks at T_cam_world into `accumulator` (and, with `map`, its
// information scaled by map_share into `map`); returns 0.5 rho, or -1 when it is behind the camera.
// Always inlined: a call per observation would cost more than the linearisations saved below.
__attribute__((always_inline)) inline double accumulatePoint(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                              const PosePointObservation& obs, const Kernels& kernels,
                              PoseNormalAccumulator* accumulator, PoseNormalAccumulator* map) {
  const Eigen::Vector3d P_cam = T_cam_world * obs.P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return -1.0;
  Eigen::Matrix3d M;
  Eigen::Vector3d q;
  double rho = 0.0, weight = 0.0;
  if (obs.has_depth) {
    Eigen::Vector3d e;
    Eigen::Matrix3d J_cam;
    stereoResidualAt(camera, P_cam, obs.z, &e, &J_cam);
    const Eigen::Vector3d omega_e = obs.information * e;
    robustCostAndWeight(kernels.stereo, e.dot(omega_e), &rho, &weight);
    stereoPointSpaceBlocks(J_cam, obs.information, omega_e, weight, &M, &q);
  } else {
    Eigen::Vector2d e;
    Matrix23d J_cam;
    monoResidualAt(camera, P_cam, obs.z.head<2>(), &e, &J_cam);
    const Eigen::Matrix2d omega = obs.information.topLeftCorner<2, 2>();
    robustCostAndWeight(kernels.mono, e.dot(omega * e), &rho, &weight);
    pointSpaceBlocks<2>(J_cam, weight * omega, e, &M, &q);
  }
  accumulator->add(M, q, P_cam);
  if (map != nullptr && obs.map_share > 0) map->add(obs.map_share * M, Eigen::Vector3d::Zero(), P_cam);
  return 0.5 * rho;
}

// The same for a line sample.
__attribute__((always_inline)) inline double accumulateLine(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                             const PoseLineObservation& obs, const Kernels& kernels,
                             PoseNormalAccumulator* accumulator, PoseNormalAccumulator* map) {
  const Eigen::Vector3d P_cam = T_cam_world * obs.P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return -1.0;
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
  accumulator->addRankOne(u, A_t_j, e * u);
  if (map != nullptr && obs.map_share > 0) map->addRankOne(obs.map_share * u, A_t_j, Vector6d::Zero());
  return 0.5 * rho;
}

// IRLS normal equations of the inliers at T_cam_world; with H_map, also the information blocks
// scaled by each observation's map_share (summed, not inverted: the map-error term of the top).
// With `sums`, the accumulated sums are also returned unfinished (for updateForNewInliers).
NormalEquations linearize(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                          const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
                          int num_lines, const Kernels& kernels, const bool* point_inliers,
                          const bool* line_inliers, Matrix6d* H_map = nullptr,
                          PoseNormalAccumulator* sums = nullptr) {
  NormalEquations ne;
  PoseNormalAccumulator accumulator, map_accumulator;
  PoseNormalAccumulator* map = H_map != nullptr ? &map_accumulator : nullptr;
  for (int i = 0; i < num_points; ++i) {
    if (!point_inliers[i]) continue;
    ne.cost += std::max(0.0, accumulatePoint(camera, T_cam_world, points[i], kernels, &accumulator, map));
  }
  for (int i = 0; i < num_lines; ++i) {
    if (!line_inliers[i]) continue;
    ne.cost += std::max(0.0, accumulateLine(camera, T_cam_world, lines[i], kernels, &accumulator, map));
  }
  accumulator.finish(&ne.H, &ne.g);
  if (sums != nullptr) *sums = accumulator;
  if (H_map != nullptr) {
    Vector6d unused;
    map_accumulator.finish(H_map, &unused);
  }
  return ne;
}

// The flags a classification changed, as normal-equation sums at the last linearisation's pose
// T_linearized: `added` for observations that became inliers, `removed` for those that stopped.
struct InlierChange {
  Eigen::Isometry3d T_linearized = Eigen::Isometry3d::Identity();
  PoseNormalAccumulator added, removed;
  int changed = 0;
};

// Re-classifies every observation and fills the inlier counts; returns how many flags changed.
// With `change`, the normal-equation sums of the changed observations at change->T_linearized.
int classify(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
              const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
              int num_lines, const PoseOptimizerOptions& options, const Kernels& kernels, bool* point_inliers,
              bool* line_inliers, PoseResult* result, InlierChange* change) {
  result->num_point_inliers = 0;
  result->num_line_inliers = 0;
  result->inlier_chi2 = InlierChi2Sums{};
  int changed = 0;
  double chi2 = 0.0;
  for (int i = 0; i < num_points; ++i) {
    const double threshold = points[i].has_depth ? options.chi2.stereo : options.chi2.mono;
    const bool inlier = pointChi2(camera, T_cam_world, points[i], &chi2) && chi2 <= threshold;
    if (inlier != point_inliers[i]) {
      ++changed;
      if (change != nullptr) {
        (void)accumulatePoint(camera, change->T_linearized, points[i], kernels,
                              inlier ? &change->added : &change->removed, nullptr);
      }
    }
    point_inliers[i] = inlier;
    result->num_point_inliers += inlier ? 1 : 0;
    if (inlier) result->inlier_chi2.add(points[i].has_depth ? 3 : 2, chi2);
  }
  for (int i = 0; i < num_lines; ++i) {
    const bool inlier = lineChi2(camera, T_cam_world, lines[i], &chi2) && chi2 <= options.chi2.line;
    if (inlier != line_inliers[i]) {
      ++changed;
      if (change != nullptr) {
        (void)accumulateLine(camera, change->T_linearized, lines[i], kernels,
                             inlier ? &change->added : &change->removed, nullptr);
      }
    }
    line_inliers[i] = inlier;
    result->num_line_inliers += inlier ? 1 : 0;
    if (inlier) result->inlier_chi2.add(1, chi2);
  }
  if (change != nullptr) change->changed = changed;
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

  // A round ends converged when its last step was below step_tolerance: its last linearisation,
  // at T_linearized, is then within the tolerance of the final pose. The next round starts from
  // those sums with only the observations whose flags changed added or removed (at T_linearized,
  // the same point as the rest), instead of linearising every observation again: the two differ
  // by less than a step the tolerance calls converged.
  PoseNormalAccumulator sums;
  InlierChange change;
  bool reuse = false;
  double last_cost = 0.0;
  for (int round = 0; round < options.rounds; ++round) {
    double lambda = options.initial_lambda;
    bool converged = false;
    for (int it = 0; it < options.iterations_per_round; ++it) {
      NormalEquations ne;
      Eigen::Isometry3d T_linearized = result.T_cam_world;
      if (reuse) {
        sums.merge(change.added, 1.0);
        sums.merge(change.removed, -1.0);
        sums.finish(&ne.H, &ne.g);
        ne.cost = last_cost;  // not read after the first round
        T_linearized = change.T_linearized;
        reuse = false;
      } else {
        ne = linearize(camera, result.T_cam_world, points, num_points, lines, num_lines, kernels, point_inliers,
                       line_inliers, nullptr, &sums);
      }
      last_cost = ne.cost;
      change.T_linearized = T_linearized;
      // The first linearisation sees every observation at the initial pose: that is the initial cost.
      if (result.iterations == 0 && round == 0 && it == 0) result.initial_cost = ne.cost;
      Matrix6d H_damped = ne.H;
      if (options.levenberg_marquardt) H_damped.diagonal() += lambda * ne.H.diagonal();
      const Eigen::LDLT<Matrix6d> ldlt(H_damped);
      if (ldlt.info() != Eigen::Success) break;
      const Vector6d delta = -ldlt.solve(ne.g);
      if (!delta.allFinite()) break;
      ++result.iterations;
      const Eigen::Isometry3d T_candidate = applyLeftIncrement(delta, T_linearized);
      if (options.levenberg_marquardt) {
        const double candidate_cost = robustCost(camera, T_candidate, points, num_points, lines, num_lines,
                                                 kernels, point_inliers, line_inliers);
        if (!(candidate_cost < ne.cost)) {
          lambda *= 10.0;
          result.T_cam_world = T_linearized;
          reuse = false;
          continue;
        }
        lambda = std::max(lambda * 0.1, 1e-12);
      }
      result.T_cam_world = T_candidate;
      if (delta.norm() < options.step_tolerance) {
        converged = true;
        break;
      }
    }
    change.added = PoseNormalAccumulator();
    change.removed = PoseNormalAccumulator();
    const int changed = classify(camera, result.T_cam_world, points, num_points, lines, num_lines, options, kernels,
                                 point_inliers, line_inliers, &result, converged ? &change : nullptr);
    // Same inlier set as this round optimised: further rounds would repeat it exactly.
    if (changed == 0) break;
    reuse = converged;
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
