#include "solver/se3.h"

#include <algorithm>
#include <cmath>

namespace plumb {
namespace {

// vee of the skew part of R: 2 sin(theta) * axis.
Eigen::Vector3d skewVee(const Eigen::Matrix3d& R) {
  return {R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1)};
}

}  // namespace

Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi) {
  const double theta2 = phi.squaredNorm();
  const double theta = std::sqrt(theta2);
  double a;  // sin(theta) / theta
  double b;  // (1 - cos(theta)) / theta^2
  if (theta < kSmallRotationAngle) {
    a = 1.0 - theta2 / 6.0;
    b = 0.5 - theta2 / 24.0;
  } else {
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta2;
  }
  const Eigen::Matrix3d K = hat(phi);
  return Eigen::Matrix3d::Identity() + a * K + b * K * K;
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  const double cos_theta = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  const Eigen::Vector3d w = skewVee(R);  // 2 sin(theta) axis
  const double sin_theta = 0.5 * w.norm();
  const double theta = std::atan2(sin_theta, cos_theta);
  if (theta < kSmallRotationAngle) {
    // theta / (2 sin theta) = 0.5 (1 + theta^2 / 6 + ...)
    return 0.5 * (1.0 + theta * theta / 6.0) * w;
  }
  if (cos_theta > -0.9) return (0.5 * theta / sin_theta) * w;
  // Near pi sin(theta) -> 0 and the skew part carries no axis information. The symmetric part is
  // cos(theta) I + (1 - cos(theta)) a a^T: read the axis from its largest diagonal entry, and
  // its sign from the (still non-zero) skew part.
  const Eigen::Matrix3d axis_outer =
      (0.5 * (R + R.transpose()) - cos_theta * Eigen::Matrix3d::Identity()) / (1.0 - cos_theta);
  int k = 0;
  axis_outer.diagonal().maxCoeff(&k);
  Eigen::Vector3d axis = axis_outer.col(k) / std::sqrt(std::max(axis_outer(k, k), 1e-300));
  axis.normalize();
  if (axis.dot(w) < 0.0) axis = -axis;
  return theta * axis;
}

Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta2 = phi.squaredNorm();
  const double theta = std::sqrt(theta2);
  double b;  // (1 - cos) / theta^2
  double c;  // (theta - sin) / theta^3
  if (theta < kSmallRotationAngle) {
    b = 0.5 - theta2 / 24.0;
    c = 1.0 / 6.0 - theta2 / 120.0;
  } else {
    b = (1.0 - std::cos(theta)) / theta2;
    c = (theta - std::sin(theta)) / (theta2 * theta);
  }
  const Eigen::Matrix3d K = hat(phi);
  return Eigen::Matrix3d::Identity() + b * K + c * K * K;
}

Eigen::Isometry3d expSE3(const Vector6d& rho_phi) {
  // expSO3(phi) and leftJacobianSO3(phi) * rho with their common terms (theta, sin, cos, K, K^2)
  // formed once: the same values, bit for bit, at about half the instructions (it runs per
  // keypoint in rolling-shutter compensation and per keyframe and iteration in the solvers).
  const Eigen::Vector3d phi = rho_phi.tail<3>();
  const double theta2 = phi.squaredNorm();
  const double theta = std::sqrt(theta2);
  double a, b, c;  // sin(theta) / theta, (1 - cos(theta)) / theta^2, (theta - sin(theta)) / theta^3
  if (theta < kSmallRotationAngle) {
    a = 1.0 - theta2 / 6.0;
    b = 0.5 - theta2 / 24.0;
    c = 1.0 / 6.0 - theta2 / 120.0;
  } else {
    const double sin_theta = std::sin(theta), cos_theta = std::cos(theta);
    a = sin_theta / theta;
    b = (1.0 - cos_theta) / theta2;
    c = (theta - sin_theta) / (theta2 * theta);
  }
  const Eigen::Matrix3d K = hat(phi);
  const Eigen::Matrix3d K2 = K * K;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Matrix3d::Identity() + a * K + b * K2;
  const Eigen::Matrix3d J = Eigen::Matrix3d::Identity() + b * K + c * K2;
  T.translation() = J * rho_phi.head<3>();
  return T;
}

Vector6d logSE3(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d phi = logSO3(T.linear());
  const double theta2 = phi.squaredNorm();
  const double theta = std::sqrt(theta2);
  // V^-1 = I - K/2 + d K^2 with d = 1/theta^2 - cot(theta/2) / (2 theta); the half-angle form
  // stays finite up to and including theta = pi.
  double d;
  if (theta < kSmallRotationAngle) {
    d = 1.0 / 12.0 + theta2 / 720.0;
  } else {
    const double half = 0.5 * theta;
    d = 1.0 / theta2 - std::cos(half) / (2.0 * theta * std::sin(half));
  }
  const Eigen::Matrix3d K = hat(phi);
  const Eigen::Matrix3d V_inv = Eigen::Matrix3d::Identity() - 0.5 * K + d * K * K;
  Vector6d out;
  out.head<3>() = V_inv * T.translation();
  out.tail<3>() = phi;
  return out;
}

Eigen::Isometry3d applyLeftIncrement(const Vector6d& delta, const Eigen::Isometry3d& T_cam_world) {
  return expSE3(delta) * T_cam_world;
}

}  // namespace plumb
