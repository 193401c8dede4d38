// solver/pose_covariance.h against sampling: the first-order covariance of a relative pose (with
// the cross-covariance of its two ends) and of a chained pose, and NEES of known errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Cholesky>

#include "solver/pose_covariance.h"
#include "solver/se3.h"

namespace plumb {
namespace {

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Vector12d = Eigen::Matrix<double, 12, 1>;

Eigen::Isometry3d pose(double a, double b, double c, double x, double y, double z) {
  Vector6d xi;
  xi << x, y, z, a, b, c;
  return expSE3(xi);
}

// Random SPD matrix with sigmas of about `scale`, cross terms included.
template <int N>
Eigen::Matrix<double, N, N> randomCovariance(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, N, N> A;
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) A(r, c) = n(rng);
  return scale * scale * (A * A.transpose() / N + 0.1 * Eigen::Matrix<double, N, N>::Identity());
}

template <int N>
Eigen::Matrix<double, N, 1> sample(const Eigen::Matrix<double, N, N>& L, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, N, 1> z;
  for (int i = 0; i < N; ++i) z(i) = n(rng);
  return L * z;
}

// The sample covariance of e = log(T_ij^-1 T_ij') with T' = exp(d) T equals the formula
// (to sampling error: 40,000 draws, sigmas ~1 mm / mrad so second-order terms are ~1e-3 of it).
TEST(PoseCovariance, RelativeCovarianceMatchesSamplingWithCrossCovariance) {
  std::mt19937 rng(7);
  const Eigen::Isometry3d T_i = pose(0.3, -0.2, 0.5, 0.4, -1.0, 2.0);
  const Eigen::Isometry3d T_j = pose(-0.1, 0.6, 0.2, 1.5, 0.3, -0.7);
  const Matrix12d C = randomCovariance<12>(rng, 1e-3);
  const Matrix12d L = C.llt().matrixL();
  const Eigen::Isometry3d T_ij = T_i * T_j.inverse();
  const int n = 40000;
  Matrix6d sum = Matrix6d::Zero();
  for (int k = 0; k < n; ++k) {
    const Vector12d d = sample<12>(L, rng);
    const Eigen::Isometry3d Ti = expSE3(d.head<6>()) * T_i, Tj = expSE3(d.tail<6>()) * T_j;
    const Vector6d e = relativePoseError(T_ij, Ti * Tj.inverse());
    sum += e * e.transpose();
  }
  const Matrix6d sampled = sum / n;
  const Matrix6d predicted =
      relativePoseCovariance(T_i, T_j, C.topLeftCorner<6, 6>(), C.bottomRightCorner<6, 6>(), C.topRightCorner<6, 6>());
  EXPECT_LT((sampled - predicted).norm(), 0.03 * predicted.norm()) << "sampled\n" << sampled << "\npredicted\n" << predicted;
  // Without the cross block the prediction is measurably different (the test can tell).
  const Matrix6d no_cross =
      relativePoseCovariance(T_i, T_j, C.topLeftCorner<6, 6>(), C.bottomRightCorner<6, 6>(), Matrix6d::Zero());
  EXPECT_GT((sampled - no_cross).norm(), 0.1 * predicted.norm());
}

TEST(PoseCovariance, FixedFirstKeyframeGivesTheSecondsMarginal) {
  std::mt19937 rng(3);
  const Matrix6d C_jj = randomCovariance<6>(rng, 1e-2);
  const Matrix6d C = relativePoseCovariance(pose(0.1, 0, 0, 0, 0, 1), pose(0, 0.2, 0, 1, 0, 0), Matrix6d::Zero(), C_jj,
                                            Matrix6d::Zero());
  EXPECT_LT((C - C_jj).norm(), 1e-15);
}

TEST(PoseCovariance, ChainMatchesSampling) {
  std::mt19937 rng(11);
  const Eigen::Isometry3d T_i = pose(0.2, 0.1, -0.4, 0.5, 0.2, 1.0);
  const Eigen::Isometry3d T_j = pose(-0.3, 0.2, 0.1, -0.2, 0.8, 0.4);
  const Matrix6d C_i = randomCovariance<6>(rng, 1e-3), C_e = randomCovariance<6>(rng, 1e-3);
  const Matrix6d L_i = C_i.llt().matrixL(), L_e = C_e.llt().matrixL();
  const Eigen::Isometry3d T_ij = T_i * T_j.inverse();
  const int n = 40000;
  Matrix6d sum = Matrix6d::Zero();
  for (int k = 0; k < n; ++k) {
    // T_j' = T_ij'^-1 T_i' with T_i' = exp(d_i) T_i and T_ij' = T_ij exp(e).
    const Eigen::Isometry3d Ti = expSE3(sample<6>(L_i, rng)) * T_i;
    const Eigen::Isometry3d Tij = T_ij * expSE3(sample<6>(L_e, rng));
    const Vector6d d_j = logSE3(Tij.inverse() * Ti * T_j.inverse());
    sum += d_j * d_j.transpose();
  }
  const Matrix6d predicted = chainPoseCovariance(T_i, T_j, C_i, C_e);
  EXPECT_LT((sum / n - predicted).norm(), 0.03 * predicted.norm());
}

TEST(PoseCovariance, NeesOfKnownErrorsAndRefusal) {
  Matrix6d C = Matrix6d::Identity() * 4.0;
  Vector6d e = Vector6d::Constant(2.0);
  EXPECT_NEAR(normalizedErrorSquared(e, C), 6.0, 1e-12);
  C(0, 0) = -1.0;
  EXPECT_TRUE(std::isnan(normalizedErrorSquared(e, C)));
}

// What local BA may publish: finite, positive definite, and its largest sigmas within the bounds
// (the largest eigenvalue of each 3x3 block: a correlated covariance whose diagonal is within the
// bound can still exceed it along a diagonal direction).
TEST(PoseCovariance, PublishableNeedsFiniteSpdAndPhysicalSigmas) {
  Vector6d sigma;
  sigma << 0.01, 0.02, 0.03, 0.001, 0.002, 0.003;
  const Matrix6d good = Matrix6d(sigma.cwiseAbs2().asDiagonal());
  EXPECT_TRUE(publishablePoseCovariance(good, 1.0, 0.5));
  Matrix6d nan = good;
  nan(2, 4) = std::nan("");
  EXPECT_FALSE(publishablePoseCovariance(nan, 1.0, 0.5));
  Matrix6d indefinite = good;
  indefinite(5, 5) = -1e-9;
  EXPECT_FALSE(publishablePoseCovariance(indefinite, 1.0, 0.5));
  EXPECT_FALSE(publishablePoseCovariance(Matrix6d::Zero(), 1.0, 0.5));
  Matrix6d far = good;
  far(1, 1) = 1.1 * 1.1;  // 1.1 m
  EXPECT_FALSE(publishablePoseCovariance(far, 1.0, 0.5));
  EXPECT_TRUE(publishablePoseCovariance(far, 2.0, 0.5));
  Matrix6d turned = good;
  turned(3, 3) = turned(4, 4) = 0.4 * 0.4;  // 0.4 rad each, correlated: 0.55 rad along (1, 1)/sqrt 2
  turned(3, 4) = turned(4, 3) = 0.9 * 0.4 * 0.4;
  EXPECT_FALSE(publishablePoseCovariance(turned, 1.0, 0.5));
  // The degenerate keyframe of synth:fast_rotation:1 (before the variance-inflation check): 3e9.
  EXPECT_FALSE(publishablePoseCovariance(3e9 * Matrix6d::Identity(), 1.0, 0.5));
}

}  // namespace
}  // namespace plumb
