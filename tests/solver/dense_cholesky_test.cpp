#include "solver/dense_cholesky.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include <Eigen/Cholesky>

namespace plumb {
namespace {

TEST(DenseCholesky, SolvesAndInvertsInTheCornerOfALargerBuffer) {
  const int n = 24;
  Eigen::MatrixXd buffer = Eigen::MatrixXd::Constant(40, 40, 99.0);  // junk outside the corner
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd A = B * B.transpose() + n * Eigen::MatrixXd::Identity(n, n);
  buffer.topLeftCorner(n, n) = A;
  ASSERT_TRUE(choleskyInPlace(buffer.topLeftCorner(n, n)));
  const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
  Eigen::VectorXd x = b;
  choleskySolveInPlace(buffer.topLeftCorner(n, n), x);
  EXPECT_LT((A * x - b).norm() / b.norm(), 1e-12);
  Eigen::MatrixXd inverse(n, n);
  choleskyInverse(buffer.topLeftCorner(n, n), inverse);
  EXPECT_LT((A * inverse - Eigen::MatrixXd::Identity(n, n)).norm(), 1e-12);
  EXPECT_TRUE(inverse.isApprox(inverse.transpose(), 0.0));
  EXPECT_TRUE(buffer.topLeftCorner(n, n).triangularView<Eigen::Lower>().toDenseMatrix().isApprox(
      Eigen::LLT<Eigen::MatrixXd>(A).matrixL().toDenseMatrix(), 1e-12));
}

// The Eigen-expression form choleskyInPlace had before it was written on column pointers and
// row pairs (issue 22, BA pass). The two must give the same bits: local BA's steps and
// covariances (and so the trajectories) come from this factor.
bool referenceCholeskyInPlace(Eigen::Ref<Eigen::MatrixXd> A) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double pivot = A(k, k);
    if (!(pivot > 0.0) || !std::isfinite(pivot)) return false;
    const double l_kk = std::sqrt(pivot);
    A(k, k) = l_kk;
    const Eigen::Index tail = n - k - 1;
    if (tail == 0) break;
    A.col(k).tail(tail) /= l_kk;
    for (Eigen::Index j = k + 1; j < n; ++j) {
      const double l_jk = A(j, k);
      A.col(j).segment(j, n - j) -= l_jk * A.col(k).segment(j, n - j);
    }
  }
  return true;
}

TEST(DenseCholesky, FactorEqualsTheEigenExpressionFormBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 1; n <= 66; n += (n < 8 ? 1 : 5)) {
    // Odd and even sizes and corner offsets: the row pairs start at odd and even rows.
    for (const Eigen::Index offset : {0, 1, 6}) {
      Eigen::MatrixXd B(n, n);
      for (Eigen::Index i = 0; i < B.size(); ++i) B(i) = u(rng);
      const Eigen::MatrixXd A = B * B.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
      Eigen::MatrixXd got = Eigen::MatrixXd::Constant(n + offset + 3, n + offset + 2, 7.0);
      got.block(offset, offset, n, n) = A;
      Eigen::MatrixXd expected = got;
      ASSERT_TRUE(choleskyInPlace(got.block(offset, offset, n, n)));
      ASSERT_TRUE(referenceCholeskyInPlace(expected.block(offset, offset, n, n)));
#if defined(__x86_64__) && !defined(__FMA__)
      for (Eigen::Index i = 0; i < got.size(); ++i) ASSERT_EQ(got(i), expected(i)) << n << " " << offset << " " << i;
#else  // aarch64 GCC fuses a - l * b differently in the two forms
      ASSERT_LT((got - expected).norm(), 1e-12 * expected.norm()) << n << " " << offset;
#endif
    }
  }
}

// The form choleskyInverse had before its forward solves started at the panel of their unit
// entry (issue 22): full solves of every unit column, then the two triangles averaged.
void referenceCholeskyInverse(const Eigen::Ref<const Eigen::MatrixXd>& L, Eigen::Ref<Eigen::MatrixXd> inverse) {
  inverse.setIdentity();
  for (Eigen::Index c = 0; c < inverse.cols(); ++c) {
    Eigen::Ref<Eigen::VectorXd> column = inverse.col(c);
    choleskySolveInPlace(L, column);
  }
  for (Eigen::Index c = 0; c < inverse.cols(); ++c) {
    for (Eigen::Index r = c + 1; r < inverse.rows(); ++r) {
      const double mean = 0.5 * (inverse(r, c) + inverse(c, r));
      inverse(r, c) = mean;
      inverse(c, r) = mean;
    }
  }
}

TEST(DenseCholesky, InverseEqualsTheFullSolveFormBitForBit) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Sizes below, at and across the solver's panel width (8), in the corner of larger buffers.
  for (int n = 1; n <= 70; n += (n < 18 ? 1 : 6)) {
    for (const Eigen::Index offset : {0, 3}) {
      Eigen::MatrixXd B(n, n);
      for (Eigen::Index i = 0; i < B.size(); ++i) B(i) = u(rng);
      Eigen::MatrixXd buffer = Eigen::MatrixXd::Constant(n + offset + 2, n + offset + 1, 5.0);
      buffer.block(offset, offset, n, n) = B * B.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
      ASSERT_TRUE(choleskyInPlace(buffer.block(offset, offset, n, n)));
      Eigen::MatrixXd got = Eigen::MatrixXd::Constant(n + 1, n + 2, -3.0);
      Eigen::MatrixXd expected = got;
      choleskyInverse(buffer.block(offset, offset, n, n), got.topLeftCorner(n, n));
      referenceCholeskyInverse(buffer.block(offset, offset, n, n), expected.topLeftCorner(n, n));
      // Bits, not values: a changed sign of a zero would count too.
      for (Eigen::Index i = 0; i < got.size(); ++i) {
        ASSERT_EQ(std::memcmp(&got(i), &expected(i), sizeof(double)), 0)
            << n << " " << offset << " " << i << ": " << got(i) << " vs " << expected(i);
      }
    }
  }
}

TEST(DenseCholesky, RejectsIndefiniteMatrices) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(4, 4);
  A(2, 2) = -1.0;
  EXPECT_FALSE(choleskyInPlace(A));
  Eigen::MatrixXd singular = Eigen::MatrixXd::Zero(3, 3);
  EXPECT_FALSE(choleskyInPlace(singular));
}

}  // namespace
}  // namespace plumb
