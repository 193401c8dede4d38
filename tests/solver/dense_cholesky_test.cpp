#include "solver/dense_cholesky.h"

#include <gtest/gtest.h>

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

TEST(DenseCholesky, RejectsIndefiniteMatrices) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(4, 4);
  A(2, 2) = -1.0;
  EXPECT_FALSE(choleskyInPlace(A));
  Eigen::MatrixXd singular = Eigen::MatrixXd::Zero(3, 3);
  EXPECT_FALSE(choleskyInPlace(singular));
}

}  // namespace
}  // namespace plumb
