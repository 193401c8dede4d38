#include "solver/pose_leverage.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "solver/factors.h"
#include "solver/robust_kernel.h"

namespace plumb {

Matrix6d poseInformation(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                         const PosePointObservation& obs, const PoseOptimizerOptions& options) {
  const Eigen::Vector3d P_cam = T_cam_world * obs.P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return Matrix6d::Zero();
  if (obs.has_depth) {
    Eigen::Vector3d e;
    Eigen::Matrix3d J_cam;
    stereoResidualAt(camera, P_cam, obs.z, &e, &J_cam);
    const double w = evaluateKernel({options.kernel, options.kernel_delta_stereo}, e.dot(obs.information * e)).rho1;
    const Eigen::Matrix<double, 3, 6> J = liftToPose<3>(J_cam, P_cam);
    return J.transpose() * (w * obs.information) * J;
  }
  Eigen::Vector2d e;
  Matrix23d J_cam;
  monoResidualAt(camera, P_cam, obs.z.head<2>(), &e, &J_cam);
  const Eigen::Matrix2d omega = obs.information.topLeftCorner<2, 2>();
  const double w = evaluateKernel({options.kernel, options.kernel_delta_mono}, e.dot(omega * e)).rho1;
  const Eigen::Matrix<double, 2, 6> J = liftToPose<2>(J_cam, P_cam);
  return J.transpose() * (w * omega) * J;
}

Matrix6d poseInformation(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_cam_world,
                         const PoseLineObservation& obs, const PoseOptimizerOptions& options) {
  const Eigen::Vector3d P_cam = T_cam_world * obs.P_world;
  if (!(P_cam.z() > kFactorMinDepth)) return Matrix6d::Zero();
  double e = 0;
  Eigen::RowVector3d J_cam;
  lineResidualAt(camera, P_cam, obs.line, &e, &J_cam);
  const double w = evaluateKernel({options.kernel, options.kernel_delta_line}, e * e * obs.information).rho1;
  const Eigen::Matrix<double, 1, 6> J = liftToPose<1>(J_cam, P_cam);
  return J.transpose() * (w * obs.information) * J;
}

double groupLeverage(const Matrix6d& covariance, const Matrix6d& group_information) {
  const Eigen::LLT<Matrix6d> llt(0.5 * (covariance + covariance.transpose()));
  if (llt.info() != Eigen::Success) return 1.0;
  const Matrix6d L = llt.matrixL();
  const Matrix6d M = L.transpose() * group_information * L;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(0.5 * (M + M.transpose()), Eigen::EigenvaluesOnly);
  return eigen.eigenvalues()(5);
}

}  // namespace plumb
