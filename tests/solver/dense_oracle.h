#pragma once
// The slow oracle beside the fast Schur path: forms the FULL normal equations of a
// LocalBundleAdjuster problem (free poses first, in variable order, then every landmark), with
// the same factors, IRLS weights and damping, so tests can solve them directly.
#include <vector>

#include <Eigen/Core>

#include "solver/factors.h"
#include "solver/local_ba.h"
#include "solver/robust_kernel.h"
#include "tests/support/synthetic_window.h"

namespace plumb::testing {

struct DenseSystem {
  Eigen::MatrixXd H;  // J^T W J
  Eigen::VectorXd g;  // J^T W e
  int pose_dim = 0;
};

inline DenseSystem buildDenseSystem(const SyntheticWindow& w, const LocalBundleAdjuster& ba,
                                    const LocalBaOptions& options) {
  DenseSystem sys;
  sys.pose_dim = 6 * ba.numPoseVariables();
  const int dim = sys.pose_dim + 3 * ba.numLandmarks();
  sys.H.setZero(dim, dim);
  sys.g.setZero(dim);
  for (const SyntheticObservation& obs : w.observations) {
    const Eigen::Isometry3d& T = ba.pose(obs.keyframe);
    const Eigen::Vector3d& P = ba.landmark(obs.landmark);
    Eigen::VectorXd e;
    Eigen::MatrixXd J_pose, J_point, omega;
    double delta = 0.0;
    bool ok = false;
    if (obs.kind == ObservationKind::kStereoPoint) {
      Eigen::Vector3d r;
      Matrix36d Jp;
      Eigen::Matrix3d Jl;
      ok = evaluateStereoPoint(w.camera, T, P, obs.z, &r, &Jp, &Jl);
      e = r, J_pose = Jp, J_point = Jl, omega = obs.information, delta = options.kernel_delta_stereo;
    } else if (obs.kind == ObservationKind::kMonoPoint) {
      Eigen::Vector2d r;
      Matrix26d Jp;
      Matrix23d Jl;
      ok = evaluateMonoPoint(w.camera, T, P, obs.z.head<2>(), &r, &Jp, &Jl);
      e = r, J_pose = Jp, J_point = Jl, omega = obs.information.topLeftCorner<2, 2>();
      delta = options.kernel_delta_mono;
    } else {
      double r = 0.0;
      RowVector6d Jp;
      Eigen::RowVector3d Jl;
      ok = evaluateLineSample(w.camera, T, P, obs.z, &r, &Jp, &Jl);
      e = Eigen::VectorXd::Constant(1, r), J_pose = Jp, J_point = Jl;
      omega = obs.information.topLeftCorner<1, 1>(), delta = options.kernel_delta_line;
    }
    if (!ok) continue;
    const double weight = evaluateKernel({options.kernel, delta}, e.dot(omega * e)).rho1;
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(e.size(), dim);
    const int v = ba.poseVariableIndex(obs.keyframe);
    if (v >= 0) J.middleCols(6 * v, 6) = J_pose;
    J.middleCols(sys.pose_dim + 3 * obs.landmark, 3) = J_point;
    sys.H += J.transpose() * (weight * omega) * J;
    sys.g += J.transpose() * (weight * omega) * e;
  }
  return sys;
}

// The LM-damped matrix, damping as documented in local_ba.h.
inline Eigen::MatrixXd dampedMatrix(const DenseSystem& sys, double lambda) {
  Eigen::MatrixXd H = sys.H;
  for (Eigen::Index d = 0; d < H.rows(); ++d) H(d, d) += lambda * std::clamp(sys.H(d, d), 1e-6, 1e32);
  return H;
}

}  // namespace plumb::testing
