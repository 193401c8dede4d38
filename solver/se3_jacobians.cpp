#include "solver/se3_jacobians.h"

#include <cmath>

#include "solver/se3.h"

namespace plumb {
namespace {

// Below this angle [rad] the coefficients of Q are taken from their series (see the header).
constexpr double kSeriesAngle = 1e-2;

// Barfoot's Q(rho, phi), the upper-right block of the SE(3) left Jacobian.
Eigen::Matrix3d couplingQ(const Eigen::Vector3d& rho, const Eigen::Vector3d& phi) {
  const double theta2 = phi.squaredNorm();
  const double theta = std::sqrt(theta2);
  double c1;  // (theta - sin) / theta^3
  double c2;  // (theta^2 + 2 cos - 2) / (2 theta^4)
  double c3;  // (2 theta - 3 sin + theta cos) / (2 theta^5)
  if (theta < kSeriesAngle) {
    const double theta4 = theta2 * theta2;
    c1 = 1.0 / 6.0 - theta2 / 120.0 + theta4 / 5040.0;
    c2 = 1.0 / 24.0 - theta2 / 720.0 + theta4 / 40320.0;
    c3 = 1.0 / 120.0 - theta2 / 2520.0 + theta4 / 120960.0;
  } else {
    const double s = std::sin(theta);
    const double c = std::cos(theta);
    const double theta4 = theta2 * theta2;
    c1 = (theta - s) / (theta2 * theta);
    c2 = (theta2 + 2.0 * c - 2.0) / (2.0 * theta4);
    c3 = (2.0 * theta - 3.0 * s + theta * c) / (2.0 * theta4 * theta);
  }
  const Eigen::Matrix3d P = hat(rho);
  const Eigen::Matrix3d K = hat(phi);
  const Eigen::Matrix3d KP = K * P;
  const Eigen::Matrix3d PK = P * K;
  const Eigen::Matrix3d KPK = KP * K;
  const Eigen::Matrix3d KKP = K * KP;
  const Eigen::Matrix3d PKK = PK * K;
  return 0.5 * P + c1 * (KP + PK + KPK) + c2 * (KKP + PKK - 3.0 * KPK) + c3 * (KPK * K + K * KPK);
}

}  // namespace

Matrix6d adjointSE3(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  Matrix6d Ad;
  Ad.topLeftCorner<3, 3>() = R;
  Ad.topRightCorner<3, 3>() = hat(T.translation()) * R;
  Ad.bottomLeftCorner<3, 3>().setZero();
  Ad.bottomRightCorner<3, 3>() = R;
  return Ad;
}

Eigen::Matrix3d leftJacobianInverseSO3(const Eigen::Vector3d& phi) {
  const double theta2 = phi.squaredNorm();
  const double theta = std::sqrt(theta2);
  double d;  // 1/theta^2 - cot(theta/2) / (2 theta), half-angle form finite up to pi
  if (theta < kSmallRotationAngle) {
    d = 1.0 / 12.0 + theta2 / 720.0;
  } else {
    const double half = 0.5 * theta;
    d = 1.0 / theta2 - std::cos(half) / (2.0 * theta * std::sin(half));
  }
  const Eigen::Matrix3d K = hat(phi);
  return Eigen::Matrix3d::Identity() - 0.5 * K + d * K * K;
}

Matrix6d leftJacobianSE3(const Vector6d& rho_phi) {
  const Eigen::Vector3d rho = rho_phi.head<3>();
  const Eigen::Vector3d phi = rho_phi.tail<3>();
  Matrix6d J;
  J.topLeftCorner<3, 3>() = leftJacobianSO3(phi);
  J.topRightCorner<3, 3>() = couplingQ(rho, phi);
  J.bottomLeftCorner<3, 3>().setZero();
  J.bottomRightCorner<3, 3>() = J.topLeftCorner<3, 3>();
  return J;
}

Matrix6d leftJacobianInverseSE3(const Vector6d& rho_phi) {
  const Eigen::Vector3d rho = rho_phi.head<3>();
  const Eigen::Vector3d phi = rho_phi.tail<3>();
  const Eigen::Matrix3d J_inv = leftJacobianInverseSO3(phi);
  Matrix6d out;
  out.topLeftCorner<3, 3>() = J_inv;
  out.topRightCorner<3, 3>() = -J_inv * couplingQ(rho, phi) * J_inv;
  out.bottomLeftCorner<3, 3>().setZero();
  out.bottomRightCorner<3, 3>() = J_inv;
  return out;
}

}  // namespace plumb
