// The Schur-complement path against the dense oracle: one damped LM step, and the covariance.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "solver/local_ba.h"
#include "tests/solver/dense_oracle.h"
#include "tests/support/synthetic_window.h"

namespace plumb::testing {
namespace {

SyntheticWindowConfig smallWindow(unsigned seed) {
  SyntheticWindowConfig config;
  config.seed = seed;
  config.num_keyframes = 5;
  config.num_fixed = 1;
  config.num_points = 40;
  config.num_lines = 6;
  config.samples_per_line = 3;
  config.views_per_landmark = 4;
  config.outlier_fraction = 0.05;  // so some IRLS weights are far from 1
  return config;
}

Eigen::VectorXd schurStep(const LocalBundleAdjuster& ba) {
  Eigen::VectorXd step(6 * ba.numPoseVariables() + 3 * ba.numLandmarks());
  for (int i = 0; i < ba.numKeyframes(); ++i) {
    if (ba.poseVariableIndex(i) >= 0) step.segment<6>(6 * ba.poseVariableIndex(i)) = ba.poseStep(i);
  }
  for (int j = 0; j < ba.numLandmarks(); ++j) {
    step.segment<3>(6 * ba.numPoseVariables() + 3 * j) = ba.landmarkStep(j);
  }
  return step;
}

TEST(LocalBaOracle, DampedSchurStepMatchesTheDenseSolve) {
  for (unsigned seed : {1u, 2u, 3u}) {
    for (double lambda : {1e-4, 1e-2, 1.0}) {
      const SyntheticWindow w = makeSyntheticWindow(smallWindow(seed));
      LocalBundleAdjuster ba;
      loadWindow(w, /*initial=*/true, &ba);
      const LocalBaOptions options;
      ASSERT_TRUE(ba.computeStep(options, lambda));
      const DenseSystem sys = buildDenseSystem(w, ba, options);
      const Eigen::VectorXd expected = dampedMatrix(sys, lambda).ldlt().solve(-sys.g);
      const Eigen::VectorXd actual = schurStep(ba);
      EXPECT_LT((actual - expected).norm() / expected.norm(), 1e-9) << "seed " << seed << " lambda " << lambda;
    }
  }
}

// Points only, so every landmark block is invertible and the dense H is too: the pose block of
// H^-1 is the covariance C = (H_A - H_B H_C^-1 H_B^T)^-1 of paper eq. 12.
TEST(LocalBaOracle, CovarianceIsThePoseBlockOfTheInverseHessian) {
  for (unsigned seed : {4u, 5u}) {
    SyntheticWindowConfig config = smallWindow(seed);
    config.num_lines = 0;
    config.outlier_fraction = 0.0;
    const SyntheticWindow w = makeSyntheticWindow(config);
    LocalBundleAdjuster ba;
    loadWindow(w, /*initial=*/false, &ba);
    const LocalBaOptions options;
    ASSERT_TRUE(ba.computeCovariance(options));
    const DenseSystem sys = buildDenseSystem(w, ba, options);
    const Eigen::MatrixXd H_inv = sys.H.ldlt().solve(Eigen::MatrixXd::Identity(sys.H.rows(), sys.H.cols()));
    const Eigen::MatrixXd expected = H_inv.topLeftCorner(sys.pose_dim, sys.pose_dim);
    const Eigen::MatrixXd actual = ba.fullCovariance();
    ASSERT_EQ(actual.rows(), sys.pose_dim);
    EXPECT_LT((actual - expected).norm() / expected.norm(), 1e-9) << seed;
    for (int i = 0; i < ba.numKeyframes(); ++i) {
      const int v = ba.poseVariableIndex(i);
      if (v < 0) {
        EXPECT_TRUE(ba.covariance(i).isZero());
        continue;
      }
      const Matrix6d block = expected.block<6, 6>(6 * v, 6 * v);
      EXPECT_LT((ba.covariance(i) - block).norm() / block.norm(), 1e-9) << seed << " keyframe " << i;
    }
  }
}

// Exact line samples: their blocks are rank 2 (a sample slides along its 3D line), so the dense
// H is singular along those directions only; the pose block of its pseudo-inverse is still the
// marginal covariance, and the Schur path (pseudo-inverting the 3x3 blocks) must match it.
TEST(LocalBaOracle, CovarianceWithRankDeficientLineSamples) {
  SyntheticWindowConfig config = smallWindow(6);
  config.num_lines = 8;
  config.pixel_noise = 0.0;
  config.depth_noise = false;
  config.outlier_fraction = 0.0;
  const SyntheticWindow w = makeSyntheticWindow(config);
  LocalBundleAdjuster ba;
  loadWindow(w, /*initial=*/false, &ba);
  const LocalBaOptions options;
  ASSERT_TRUE(ba.computeCovariance(options));
  const DenseSystem sys = buildDenseSystem(w, ba, options);
  // Eliminate each landmark block with an eigen-decomposition pseudo-inverse, densely.
  Eigen::MatrixXd S = sys.H.topLeftCorner(sys.pose_dim, sys.pose_dim);
  for (int j = 0; j < ba.numLandmarks(); ++j) {
    const int c = sys.pose_dim + 3 * j;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(sys.H.block<3, 3>(c, c));
    Eigen::Matrix3d pinv = Eigen::Matrix3d::Zero();
    for (int d = 0; d < 3; ++d) {
      if (eig.eigenvalues()(d) > 1e-10 * eig.eigenvalues()(2)) {
        pinv += eig.eigenvectors().col(d) * eig.eigenvectors().col(d).transpose() / eig.eigenvalues()(d);
      }
    }
    const Eigen::MatrixXd H_pl = sys.H.block(0, c, sys.pose_dim, 3);
    S -= H_pl * pinv * H_pl.transpose();
  }
  const Eigen::MatrixXd expected = S.inverse();
  const Eigen::MatrixXd actual = ba.fullCovariance();
  EXPECT_LT((actual - expected).norm() / expected.norm(), 1e-9);
}

}  // namespace
}  // namespace plumb::testing
