#include "solver/se3.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace plumb {
namespace {

Eigen::Vector3d randomAxis(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
}

TEST(So3, ExpIsARotation) {
  std::mt19937 rng(3);
  for (double angle : {0.0, 1e-12, 1e-7, 1e-3, 0.5, 2.0, M_PI - 1e-6, M_PI}) {
    const Eigen::Matrix3d R = expSO3(angle * randomAxis(rng));
    EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14) << angle;
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14) << angle;
  }
}

TEST(So3, ExpMatchesEigenAngleAxis) {
  std::mt19937 rng(4);
  for (double angle : {1e-5, 0.3, 1.7, 3.0}) {
    const Eigen::Vector3d axis = randomAxis(rng);
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_LT((expSO3(angle * axis) - expected).norm(), 1e-14) << angle;
  }
}

// exp(log(R)) = R and log(exp(phi)) = phi for |phi| < pi, across tiny, moderate and near-pi angles.
TEST(So3, RoundTripsIncludingTinyAndNearPiAngles) {
  std::mt19937 rng(5);
  const double angles[] = {0.0, 1e-15, 1e-10, 1e-8, 1e-5, 1e-4, 1.1e-4, 1e-2, 0.7, 2.0, 2.7,
                           3.0, M_PI - 1e-3, M_PI - 1e-6, M_PI - 1e-9};
  for (double angle : angles) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Vector3d phi = angle * randomAxis(rng);
      const Eigen::Vector3d back = logSO3(expSO3(phi));
      EXPECT_LE((back - phi).norm(), 1e-12 * angle) << "angle " << angle << " trial " << trial;
      EXPECT_LT((expSO3(back) - expSO3(phi)).norm(), 1e-13) << angle;
    }
  }
}

TEST(So3, LogOfExactlyPiRotation) {
  // Rotation by pi about a unit axis a: R = 2 a a^T - I. log must return +-pi a.
  std::mt19937 rng(6);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d a = randomAxis(rng);
    const Eigen::Matrix3d R = 2.0 * a * a.transpose() - Eigen::Matrix3d::Identity();
    const Eigen::Vector3d phi = logSO3(R);
    EXPECT_NEAR(phi.norm(), M_PI, 1e-12);
    EXPECT_NEAR(std::abs(phi.normalized().dot(a)), 1.0, 1e-12);
    EXPECT_LT((expSO3(phi) - R).norm(), 1e-12);
  }
}

TEST(Se3, RoundTrips) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  for (double angle : {0.0, 1e-12, 1e-6, 0.2, 1.5, 3.0, M_PI - 1e-7}) {
    for (int trial = 0; trial < 20; ++trial) {
      Vector6d xi;
      xi.head<3>() = Eigen::Vector3d(g(rng), g(rng), g(rng));
      xi.tail<3>() = angle * randomAxis(rng);
      const Eigen::Isometry3d T = expSE3(xi);
      const Vector6d back = logSE3(T);
      EXPECT_LT((expSE3(back).matrix() - T.matrix()).norm(), 1e-12) << angle;
      if (angle < 3.0) {
        EXPECT_LT((back - xi).norm(), 1e-11) << angle;
      }
    }
  }
}

TEST(Se3, ExpOfPureTranslation) {
  Vector6d xi;
  xi << 1.0, -2.0, 3.0, 0.0, 0.0, 0.0;
  const Eigen::Isometry3d T = expSE3(xi);
  EXPECT_TRUE(T.linear().isIdentity(0.0));
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(1.0, -2.0, 3.0)));
}

// The documented convention: d (exp(delta) T P) / d delta = [I | -[T P]x].
TEST(Se3, LeftPerturbationJacobianOfAPoint) {
  Vector6d xi;
  xi << 0.3, -0.2, 1.0, 0.4, -0.5, 0.2;
  const Eigen::Isometry3d T = expSE3(xi);
  const Eigen::Vector3d P(0.7, -1.1, 2.5);
  const Eigen::Vector3d P_cam = T * P;
  Eigen::Matrix<double, 3, 6> expected;
  expected << Eigen::Matrix3d::Identity(), -hat(P_cam);
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Vector6d d = Vector6d::Zero();
    d(k) = h;
    const Eigen::Vector3d column = (applyLeftIncrement(d, T) * P - applyLeftIncrement(-d, T) * P) / (2.0 * h);
    EXPECT_LT((column - expected.col(k)).norm(), 1e-8) << k;
  }
}

TEST(Se3, HatIsCrossProduct) {
  const Eigen::Vector3d a(1.0, 2.0, -3.0);
  const Eigen::Vector3d b(-0.5, 4.0, 0.25);
  EXPECT_TRUE((hat(a) * b).isApprox(a.cross(b)));
}

}  // namespace
}  // namespace plumb
