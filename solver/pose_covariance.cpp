#include "solver/pose_covariance.h"

#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "solver/se3.h"
#include "solver/se3_jacobians.h"

namespace plumb {

Matrix6d relativePoseCovariance(const Eigen::Isometry3d& T_i_cam_world, const Eigen::Isometry3d& T_j_cam_world,
                                const Matrix6d& C_ii, const Matrix6d& C_jj, const Matrix6d& C_ij) {
  const Matrix6d A = adjointSE3(T_j_cam_world * T_i_cam_world.inverse());
  const Matrix6d cross = A * C_ij;
  const Matrix6d C = A * C_ii * A.transpose() + C_jj - cross - cross.transpose();
  return 0.5 * (C + C.transpose());
}

Matrix6d chainPoseCovariance(const Eigen::Isometry3d& T_i_cam_world, const Eigen::Isometry3d& T_j_cam_world,
                             const Matrix6d& covariance_i, const Matrix6d& relative_covariance) {
  const Matrix6d A = adjointSE3(T_j_cam_world * T_i_cam_world.inverse());
  const Matrix6d C = A * covariance_i * A.transpose() + relative_covariance;
  return 0.5 * (C + C.transpose());
}

Vector6d relativePoseError(const Eigen::Isometry3d& T_i_j_true, const Eigen::Isometry3d& T_i_j_estimate) {
  return logSE3(T_i_j_true.inverse() * T_i_j_estimate);
}

bool poseSigmasWithin(const Matrix6d& covariance, double max_translation_sigma, double max_rotation_sigma) {
  // SelfAdjointEigenSolver reads the lower triangle only.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> t(covariance.topLeftCorner<3, 3>(), Eigen::EigenvaluesOnly);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> r(covariance.bottomRightCorner<3, 3>(), Eigen::EigenvaluesOnly);
  return t.info() == Eigen::Success && r.info() == Eigen::Success &&
         t.eigenvalues().maxCoeff() <= max_translation_sigma * max_translation_sigma &&
         r.eigenvalues().maxCoeff() <= max_rotation_sigma * max_rotation_sigma;
}

bool publishablePoseCovariance(const Matrix6d& covariance, double max_translation_sigma, double max_rotation_sigma) {
  if (!covariance.allFinite()) return false;
  const Matrix6d symmetric = 0.5 * (covariance + covariance.transpose());
  if (Eigen::LLT<Matrix6d>(symmetric).info() != Eigen::Success) return false;
  return poseSigmasWithin(symmetric, max_translation_sigma, max_rotation_sigma);
}

double normalizedErrorSquared(const Vector6d& error, const Matrix6d& covariance) {
  const Eigen::LLT<Matrix6d> llt(0.5 * (covariance + covariance.transpose()));
  if (llt.info() != Eigen::Success || !covariance.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  return error.dot(llt.solve(error));
}

}  // namespace plumb
