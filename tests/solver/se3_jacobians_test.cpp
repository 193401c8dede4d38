// SE(3) adjoint and left Jacobians against their defining identities, by finite differences.
#include "solver/se3_jacobians.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "solver/se3.h"

namespace plumb {
namespace {

Vector6d tangentWithAngle(std::mt19937& rng, double angle, double translation) {
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  Vector6d xi;
  xi << translation * Eigen::Vector3d(g(rng), g(rng), g(rng)), angle * axis;
  return xi;
}

TEST(Se3Jacobians, AdjointMovesATangentThroughAPose) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Isometry3d T = expSE3(tangentWithAngle(rng, 2.0, 1.5));
    const Vector6d xi = tangentWithAngle(rng, 0.7, 0.5);
    const Eigen::Isometry3d lhs = T * expSE3(xi) * T.inverse();
    const Eigen::Isometry3d rhs = expSE3(adjointSE3(T) * xi);
    EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-12);
  }
}

// J_l(xi) d = logSE3(expSE3(xi + d) expSE3(xi)^-1) / first order, column by column.
TEST(Se3Jacobians, LeftJacobianMatchesCentralDifferences) {
  std::mt19937 rng(12);
  const double h = 1e-6;
  for (double angle : {0.0, 1e-6, 5e-3, 0.011, 0.4, 1.5, 2.8, M_PI - 1e-3}) {
    for (int trial = 0; trial < 5; ++trial) {
      const Vector6d xi = tangentWithAngle(rng, angle, 1.0);
      Matrix6d numeric;
      const Eigen::Isometry3d T_inv = expSE3(xi).inverse();
      for (int c = 0; c < 6; ++c) {
        const Vector6d d = h * Vector6d::Unit(c);
        numeric.col(c) = (logSE3(expSE3(xi + d) * T_inv) - logSE3(expSE3(xi - d) * T_inv)) / (2.0 * h);
      }
      const Matrix6d analytic = leftJacobianSE3(xi);
      EXPECT_LT((analytic - numeric).norm(), 1e-7 * std::max(1.0, numeric.norm())) << "angle " << angle;
    }
  }
}

TEST(Se3Jacobians, ClosedFormInverseIsTheInverse) {
  std::mt19937 rng(13);
  for (double angle : {0.0, 1e-9, 1e-5, 9e-3, 0.0101, 0.3, 2.0, 3.1, M_PI}) {
    for (int trial = 0; trial < 5; ++trial) {
      const Vector6d xi = tangentWithAngle(rng, angle, 2.0);
      const Matrix6d product = leftJacobianSE3(xi) * leftJacobianInverseSE3(xi);
      // Near pi J_l is nearly singular (its SO(3) block has eigenvalue ~ sin(theta)/theta -> 0),
      // so the product's rounding grows like the inverse's norm.
      const double tolerance = 1e-12 * std::max(1.0, leftJacobianInverseSE3(xi).norm());
      EXPECT_LT((product - Matrix6d::Identity()).norm(), tolerance) << "angle " << angle;
      const Eigen::Vector3d phi = xi.tail<3>();
      EXPECT_LT((leftJacobianSO3(phi) * leftJacobianInverseSO3(phi) - Eigen::Matrix3d::Identity()).norm(),
                tolerance);
    }
  }
}

// The property the pose graph relies on: logSE3(expSE3(x) E) = e + J_l(e)^-1 x + O(|x|^2).
TEST(Se3Jacobians, InverseLeftJacobianLinearisesLogOfALeftIncrement) {
  std::mt19937 rng(14);
  const double h = 1e-6;
  for (double angle : {1e-3, 0.5, 2.5}) {
    const Vector6d e = tangentWithAngle(rng, angle, 1.0);
    const Eigen::Isometry3d E = expSE3(e);
    Matrix6d numeric;
    for (int c = 0; c < 6; ++c) {
      const Vector6d d = h * Vector6d::Unit(c);
      numeric.col(c) = (logSE3(expSE3(d) * E) - logSE3(expSE3(-d) * E)) / (2.0 * h);
    }
    EXPECT_LT((leftJacobianInverseSE3(e) - numeric).norm(), 1e-7 * std::max(1.0, numeric.norm())) << angle;
  }
}

}  // namespace
}  // namespace plumb
