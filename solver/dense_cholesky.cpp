#include "solver/dense_cholesky.h"

#include <cmath>

#include "solver/schur_kernels.h"

namespace plumb {

// Right-looking column Cholesky on the lower triangle. Column-major storage makes the inner loops
// contiguous. Written on raw column pointers: Eigen's dynamic-size segment expressions set up an
// alignment prologue and epilogue for every column of every trailing update, which was about half
// of the instructions for n = 60 (issue 22, BA pass). Every entry gets the same operations in the
// same order as that form (a / l_kk, then a - l_jk * l_ik for k = 0, 1, ...), so the factor is
// bit-identical to it (tests/solver/dense_cholesky_test.cpp keeps it as the reference).
bool choleskyInPlace(Eigen::Ref<Eigen::MatrixXd> A) {
  using schur_detail::Double2;
  const Eigen::Index n = A.rows();
  const Eigen::Index stride = A.outerStride();
  double* const a = A.data();
  for (Eigen::Index k = 0; k < n; ++k) {
    double* const col_k = a + k * stride;
    const double pivot = col_k[k];
    if (!(pivot > 0.0) || !std::isfinite(pivot)) return false;
    const double l_kk = std::sqrt(pivot);
    col_k[k] = l_kk;
    for (Eigen::Index i = k + 1; i < n; ++i) col_k[i] /= l_kk;
    // Trailing update A22 -= l21 l21^T, lower triangle only, column by column: an odd first row
    // alone, then row pairs, then an odd last row (elementwise, so the pairing changes no bits).
    for (Eigen::Index j = k + 1; j < n; ++j) {
      const double l_jk = col_k[j];
      double* const col_j = a + j * stride;
      Eigen::Index i = j;
      if ((n - i) & 1) {
        col_j[i] -= l_jk * col_k[i];
        ++i;
      }
      const Double2 l2 = schur_detail::splat(l_jk);
      for (; i < n; i += 2) {
        schur_detail::store2(col_j + i, schur_detail::load2(col_j + i) - l2 * schur_detail::load2(col_k + i));
      }
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
  const Eigen::Index n = inverse.cols();
  // Column c solves L y = e_c, then L^T x = y. Eigen's forward solve works in panels of
  // EIGEN_TUNE_TRIANGULAR_PANEL_WIDTH rows from row 0: inside a panel it skips the zero entries of
  // y, and below a panel each row gets one matrix-vector sum over the panel's columns, which is
  // exactly +0 for the panels above row c (y is zero there) and leaves the +0 rows unchanged. So
  // the forward solve on the trailing block from the first row of c's panel (panels at the same
  // offsets, the same sums per entry) gives the same bits without the panels of zeros (issue 22:
  // about a third of the instructions of this function). The backward solve reads all of y.
  const Eigen::Index panel = EIGEN_TUNE_TRIANGULAR_PANEL_WIDTH;
  for (Eigen::Index c = 0; c < n; ++c) {
    const Eigen::Index start = c - c % panel;
    Eigen::Ref<Eigen::VectorXd> column = inverse.col(c);
    L.bottomRightCorner(n - start, n - start).triangularView<Eigen::Lower>().solveInPlace(column.tail(n - start));
    L.triangularView<Eigen::Lower>().transpose().solveInPlace(column);
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
