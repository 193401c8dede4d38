// The fast paths of the solvers' inner loops against straightforward Eigen references written
// from their definitions: the stereo point-space blocks (solver/point_space_blocks.h), the pose
// block lifted from them, and the small kernels of the landmark elimination
// (solver/schur_kernels.h; its diagonal-block variant writes the lower triangle only). They
// compute the same sums in another order, so the comparisons are to a relative 1e-12, which any
// wrong index or sign misses by far.
#include <random>

#include <gtest/gtest.h>

#include "solver/factors.h"
#include "solver/point_space_blocks.h"
#include "solver/schur_kernels.h"
#include "solver/se3.h"

namespace plumb {
namespace {

constexpr double kTolerance = 1e-12;

template <typename A, typename B>
double relativeError(const A& got, const B& expected) {
  return (got - expected).norm() / std::max(1.0, expected.norm());
}

Eigen::Matrix3d randomInformation(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i) = u(rng);
  return A * A.transpose() + 0.1 * Eigen::Matrix3d::Identity();  // symmetric positive definite
}

TEST(SolverKernels, StereoPointSpaceBlocksEqualJtWJ) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const CameraIntrinsics camera{525.0, 523.0, 319.5, 239.5, 40.0};
  for (int n = 0; n < 500; ++n) {
    const Eigen::Vector3d P_cam(2.0 * u(rng), 1.5 * u(rng), 2.5 + 2.0 * u(rng));
    const Eigen::Vector3d z(300 + 100 * u(rng), 200 + 100 * u(rng), 290 + 100 * u(rng));
    Eigen::Vector3d e;
    Eigen::Matrix3d J_cam;
    stereoResidualAt(camera, P_cam, z, &e, &J_cam);
    const Eigen::Matrix3d omega = randomInformation(rng);
    const double weight = 0.5 + 0.5 * u(rng);
    Eigen::Matrix3d M;
    Eigen::Vector3d q;
    stereoPointSpaceBlocks(J_cam, omega, omega * e, weight, &M, &q);
    const Eigen::Matrix3d M_expected = J_cam.transpose() * (weight * omega) * J_cam;
    const Eigen::Vector3d q_expected = J_cam.transpose() * (weight * omega) * e;
    ASSERT_LT(relativeError(M, M_expected), kTolerance) << n;
    ASSERT_LT(relativeError(q, q_expected), kTolerance) << n;
    // The general path agrees too (it is what mono points still use).
    Eigen::Matrix3d M_general;
    Eigen::Vector3d q_general;
    pointSpaceBlocks<3>(J_cam, Eigen::Matrix3d(weight * omega), e, &M_general, &q_general);
    ASSERT_LT(relativeError(M_general, M_expected), kTolerance) << n;
    ASSERT_LT(relativeError(q_general, q_expected), kTolerance) << n;
  }
}

TEST(SolverKernels, PoseNormalAccumulatorEqualsLiftedJacobianProducts) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PoseNormalAccumulator accumulator;
  Matrix6d H_expected = Matrix6d::Zero();
  Vector6d g_expected = Vector6d::Zero();
  for (int n = 0; n < 50; ++n) {
    const Eigen::Vector3d P(u(rng), u(rng), 2.0 + u(rng));
    const Eigen::Matrix3d M = randomInformation(rng);
    const Eigen::Vector3d q(u(rng), u(rng), u(rng));
    accumulator.add(M, q, P);
    const Matrix36d A = pointPoseJacobian(P);  // [I | -[P]x]
    H_expected += A.transpose() * M * A;
    g_expected += A.transpose() * q;
  }
  Matrix6d H;
  Vector6d g;
  accumulator.finish(&H, &g);
  EXPECT_LT(relativeError(H, H_expected), kTolerance);
  EXPECT_LT(relativeError(g, g_expected), kTolerance);
}

TEST(SolverKernels, SchurBlockKernelsEqualEigenProducts) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 0; n < 200; ++n) {
    Matrix63d W, V_in;
    for (int i = 0; i < 18; ++i) W(i) = u(rng), V_in(i) = u(rng);
    const Eigen::Matrix3d H = randomInformation(rng);
    const Eigen::Vector3d g(u(rng), u(rng), u(rng));
    Vector6d rhs;
    for (int i = 0; i < 6; ++i) rhs(i) = u(rng);
    const Vector6d rhs_expected = rhs + W * H * g;
    Matrix63d V;
    formVAndRhs(W, H, g, &V, rhs.data());
    ASSERT_LT(relativeError(V, Matrix63d(W * H)), kTolerance) << n;
    ASSERT_LT(relativeError(rhs, rhs_expected), kTolerance) << n;

    // A 6x6 block inside a larger column-major matrix (odd offset and stride): only the block
    // changes.
    Eigen::MatrixXd S = Eigen::MatrixXd::Random(20, 17);
    const Eigen::MatrixXd before = S;
    subtractVWt(V_in, W, &S(3, 5), S.outerStride());
    Eigen::MatrixXd expected = before;
    expected.block<6, 6>(3, 5) -= V_in * W.transpose();
    ASSERT_LT(relativeError(S, expected), kTolerance) << n;
    Eigen::MatrixXd outside = S - before;
    outside.block<6, 6>(3, 5).setZero();
    ASSERT_EQ(outside.cwiseAbs().maxCoeff(), 0.0) << n;

    // The diagonal-block variant: the lower triangle bit-identical to the full kernel's, the
    // strict upper triangle beyond the 2x2 pairs on the diagonal untouched.
    Eigen::MatrixXd lower = before;
    subtractVWtLower(V_in, W, &lower(3, 5), lower.outerStride());
    for (int c = 0; c < 6; ++c) {
      for (int r = 0; r < 6; ++r) {
        if (r >= c) {
          ASSERT_EQ(lower(3 + r, 5 + c), S(3 + r, 5 + c)) << n << " " << r << " " << c;
        } else if (r < (c & ~1)) {
          ASSERT_EQ(lower(3 + r, 5 + c), before(3 + r, 5 + c)) << n << " " << r << " " << c;
        }
      }
    }
  }
}

TEST(SolverKernels, RankOneLineSampleBlocksEqualTheGeneralForms) {
  // Line samples: with j = J_cam^T and c = w Omega, A^T M A = u (A^T j)^T (addRankOne) and
  // V_a W_b^T = u_a (r_a^T H^-1 r_b) u_b^T (subtractScaledOuter[Lower]), against the 3x3 M forms.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const CameraIntrinsics camera{525.0, 523.0, 319.5, 239.5, 40.0};
  for (int n = 0; n < 200; ++n) {
    const Eigen::Matrix3d R = expSO3(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    Eigen::Vector3d P_cam[2], r[2];
    Vector6d A_t_j[2], u_vec[2];
    Matrix63d W[2];
    PoseNormalAccumulator general, rank_one;
    for (int k = 0; k < 2; ++k) {
      P_cam[k] = Eigen::Vector3d(2.0 * u(rng), 1.5 * u(rng), 2.5 + 2.0 * u(rng));
      const Eigen::Vector3d line = Eigen::Vector3d(u(rng), u(rng), 100 * u(rng));
      double e = 0.0;
      Eigen::RowVector3d J_cam;
      lineResidualAt(camera, P_cam[k], line, &e, &J_cam);
      const double c = 0.5 + 0.5 * u(rng);
      const Eigen::Vector3d j = J_cam.transpose();
      const Eigen::Matrix3d M = c * j * J_cam;
      general.add(M, c * e * j, P_cam[k]);
      A_t_j[k] << j, P_cam[k].cross(j);
      u_vec[k] = c * A_t_j[k];
      rank_one.addRankOne(u_vec[k], A_t_j[k], e * u_vec[k]);
      r[k] = R.transpose() * j;
      const Eigen::Matrix3d MR = M * R;
      W[k].topRows<3>() = MR;
      for (int col = 0; col < 3; ++col) W[k].block<3, 1>(3, col) = P_cam[k].cross(MR.col(col));
      ASSERT_LT(relativeError(Matrix63d(u_vec[k] * r[k].transpose()), W[k]), kTolerance) << n;
    }
    Matrix6d H_general, H_rank_one;
    Vector6d g_general, g_rank_one;
    general.finish(&H_general, &g_general);
    rank_one.finish(&H_rank_one, &g_rank_one);
    ASSERT_LT(relativeError(H_rank_one, H_general), kTolerance) << n;
    ASSERT_LT(relativeError(g_rank_one, g_general), kTolerance) << n;

    const Eigen::Matrix3d H_inv = randomInformation(rng);
    const double gamma = r[0].dot(H_inv * r[1]);
    const Matrix6d expected = -(W[1] * H_inv) * W[0].transpose();  // S_10 -= V_1 W_0^T
    Matrix6d S = Matrix6d::Zero();
    subtractScaledOuter(gamma, u_vec[1].data(), u_vec[0].data(), S.data(), 6);
    // gamma = r_1^T H^-1 r_0 can cancel to far below its terms, so the two orders of summation
    // agree to eps times the size of the terms, not of the result: scale by the factors' norms.
    // (The aarch64 build failed at 3.7e-12 relative to the result under qemu in CI: GCC fuses
    // a * b + c into FMA there, so the last bits, and with them the cancellation, differ.)
    const double term_scale = W[1].norm() * H_inv.norm() * W[0].norm();
    ASSERT_LT((S - expected).norm() / std::max(1.0, term_scale), kTolerance) << n;
    const Matrix6d expected_diagonal = -(W[0] * H_inv) * W[0].transpose();
    Matrix6d S_lower = Matrix6d::Zero();
    subtractScaledOuterLower(r[0].dot(H_inv * r[0]), u_vec[0].data(), u_vec[0].data(), S_lower.data(), 6);
    // Lower triangle as the Cholesky reads it (row pairs from (c & ~1) down may also hold entries
    // just above the diagonal, written with the same values).
    for (int col = 0; col < 6; ++col) {
      for (int row = col; row < 6; ++row) {
        ASSERT_NEAR(S_lower(row, col), expected_diagonal(row, col),
                    kTolerance * std::max(1.0, W[0].norm() * H_inv.norm() * W[0].norm()))
            << n << " (" << row << ", " << col << ")";
      }
    }
  }
}

}  // namespace
}  // namespace plumb
