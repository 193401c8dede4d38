#include "solver/pose_optimizer.h"

#include <Eigen/Cholesky>

#include "solver/factors.h"
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

// IRLS normal equations of the inliers at T_cam_world.
NormalEquations linearize(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                          const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
                          int num_lines, const Kernels& kernels, const bool* point_inliers,
                          const bool* line_inliers) {
  NormalEquations ne;
  for (int i = 0; i < num_points; ++i) {
    if (!point_inliers[i]) continue;
    const PosePointObservation& obs = points[i];
    if (obs.has_depth) {
      Eigen::Vector3d e;
      Matrix36d J;
      if (!evaluateStereoPoint(camera, T_cam_world, obs.P_world, obs.z, &e, &J, nullptr)) continue;
      const Eigen::Vector3d omega_e = obs.information * e;
      const double chi2 = e.dot(omega_e);
      const RobustKernelValue k = evaluateKernel(kernels.stereo, chi2);
      const Matrix63d Jt_omega = k.rho1 * J.transpose() * obs.information;
      ne.H.noalias() += Jt_omega * J;
      ne.g.noalias() += Jt_omega * e;
      ne.cost += 0.5 * k.rho;
    } else {
      Eigen::Vector2d e;
      Matrix26d J;
      if (!evaluateMonoPoint(camera, T_cam_world, obs.P_world, obs.z.head<2>(), &e, &J, nullptr)) continue;
      const Eigen::Matrix2d omega = obs.information.topLeftCorner<2, 2>();
      const double chi2 = e.dot(omega * e);
      const RobustKernelValue k = evaluateKernel(kernels.mono, chi2);
      const Eigen::Matrix<double, 6, 2> Jt_omega = k.rho1 * J.transpose() * omega;
      ne.H.noalias() += Jt_omega * J;
      ne.g.noalias() += Jt_omega * e;
      ne.cost += 0.5 * k.rho;
    }
  }
  for (int i = 0; i < num_lines; ++i) {
    if (!line_inliers[i]) continue;
    const PoseLineObservation& obs = lines[i];
    double e;
    RowVector6d J;
    if (!evaluateLineSample(camera, T_cam_world, obs.P_world, obs.line, &e, &J, nullptr)) continue;
    const double chi2 = e * e * obs.information;
    const RobustKernelValue k = evaluateKernel(kernels.line, chi2);
    const double w = k.rho1 * obs.information;
    ne.H.noalias() += (w * J.transpose()) * J;
    ne.g.noalias() += (w * e) * J.transpose();
    ne.cost += 0.5 * k.rho;
  }
  return ne;
}

// Re-classifies every observation; returns the inlier counts.
void classify(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
              const PosePointObservation* points, int num_points, const PoseLineObservation* lines,
              int num_lines, const PoseOptimizerOptions& options, bool* point_inliers, bool* line_inliers,
              PoseResult* result) {
  result->num_point_inliers = 0;
  result->num_line_inliers = 0;
  double chi2 = 0.0;
  for (int i = 0; i < num_points; ++i) {
    const double threshold = points[i].has_depth ? options.chi2_stereo : options.chi2_mono;
    point_inliers[i] = pointChi2(camera, T_cam_world, points[i], &chi2) && chi2 <= threshold;
    result->num_point_inliers += point_inliers[i] ? 1 : 0;
  }
  for (int i = 0; i < num_lines; ++i) {
    line_inliers[i] = lineChi2(camera, T_cam_world, lines[i], &chi2) && chi2 <= options.chi2_line;
    result->num_line_inliers += line_inliers[i] ? 1 : 0;
  }
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
  for (int i = 0; i < num_points; ++i) point_inliers[i] = true;
  for (int i = 0; i < num_lines; ++i) line_inliers[i] = true;
  result.initial_cost =
      robustCost(camera, T_cam_world_initial, points, num_points, lines, num_lines, kernels, nullptr, nullptr);

  for (int round = 0; round < options.rounds; ++round) {
    double lambda = options.initial_lambda;
    for (int it = 0; it < options.iterations_per_round; ++it) {
      const NormalEquations ne = linearize(camera, result.T_cam_world, points, num_points, lines, num_lines,
                                           kernels, point_inliers, line_inliers);
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
    classify(camera, result.T_cam_world, points, num_points, lines, num_lines, options, point_inliers,
             line_inliers, &result);
  }

  const NormalEquations ne = linearize(camera, result.T_cam_world, points, num_points, lines, num_lines,
                                       kernels, point_inliers, line_inliers);
  result.final_cost = ne.cost;
  const Eigen::LLT<Matrix6d> llt(ne.H);
  if (llt.info() == Eigen::Success) {
    result.covariance = llt.solve(Matrix6d::Identity());
    result.covariance_valid = result.covariance.allFinite();
  }
  return result;
}

}  // namespace plumb
