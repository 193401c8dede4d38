#include "solver/dense_cholesky.h"

#include <cmath>

namespace plumb {

// Right-looking column Cholesky on the lower triangle. Column-major storage makes the inner loops
// contiguous; for n = 60 this is ~36k multiply-adds, negligible next to the Schur products.
bool choleskyInPlace(Eigen::Ref<Eigen::MatrixXd> A) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double pivot = A(k, k);
    if (!(pivot > 0.0) || !std::isfinite(pivot)) return false;
    const double l_kk = std::sqrt(pivot);
    A(k, k) = l_kk;
    const Eigen::Index tail = n - k - 1;
    if (tail == 0) break;
    A.col(k).tail(tail) /= l_kk;
    // Trailing update A22 -= l21 l21^T, lower triangle only, column by column.
    for (Eigen::Index j = k + 1; j < n; ++j) {
      const double l_jk = A(j, k);
      A.col(j).segment(j, n - j) -= l_jk * A.col(k).segment(j, n - j);
    }
  }
  return true;
}

void choleskySolveInPlace(const Eigen::Ref<const Eigen::MatrixXd>& L, Eigen::Ref<Eigen::VectorXd> b) {
  L.triangularView<Eigen::Lower>().solveInPlace(b);
  L.triangularView<Eigen::Lower>().transpose().solveInPlace(b);
}

void choleskyInverse(const Eigen::Ref<const Eigen::MatrixXd>& L, Eigen::Ref<Eigen::MatrixXd> inverse) {
  inverse.setIdentity();
  for (Eigen::Index c = 0; c < inverse.cols(); ++c) {
    Eigen::Ref<Eigen::VectorXd> column = inverse.col(c);
    choleskySolveInPlace(L, column);
  }
  // Average the two triangles so the result is exactly symmetric (in place: no temporary).
  for (Eigen::Index c = 0; c < inverse.cols(); ++c) {
    for (Eigen::Index r = c + 1; r < inverse.rows(); ++r) {
      const double mean = 0.5 * (inverse(r, c) + inverse(c, r));
      inverse(r, c) = mean;
      inverse(c, r) = mean;
    }
  }
}

}  // namespace plumb
