#pragma once
// The small products of the landmark elimination in local BA (local_ba_linearization.cpp),
// written on 2-double vectors (GCC/Clang vector extensions: SSE2 on x86-64, NEON on aarch64).
//
// Why not Eigen's `S.block<6, 6>(..) -= V * W.transpose()`: GCC compiles it column by column and
// reloads all of V for every column of the result (55 instructions per column, ~330 a block; it
// was 63% of the elimination on fr1/rpy). Here V stays in 9 registers and each column costs its
// 3 broadcasts, 9 multiplies, 9 subtractions and 3 loads and stores (~180 a block). The sums
// are the same products added in a fixed order, so results are deterministic; they differ
// from Eigen's only in rounding. tests/solver/schur_kernels_test.cpp checks both against Eigen.
#include <cstring>

#include <Eigen/Core>

#include "solver/types.h"

namespace plumb {
namespace schur_detail {

typedef double Double2 __attribute__((vector_size(16)));

inline Double2 load2(const double* p) {
  Double2 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
inline void store2(double* p, Double2 v) { std::memcpy(p, &v, sizeof(v)); }
inline Double2 splat(double x) { return Double2{x, x}; }

}  // namespace schur_detail

// S_block -= V W^T, S_block the 6x6 block of a column-major matrix starting at `S` with column
// stride `stride` (doubles), V and W 6x3 (column-major).
inline void subtractVWt(const Matrix63d& V, const Matrix63d& W, double* S, Eigen::Index stride) {
  using namespace schur_detail;
  const double* v = V.data();
  const Double2 v00 = load2(v), v01 = load2(v + 2), v02 = load2(v + 4);      // column 0
  const Double2 v10 = load2(v + 6), v11 = load2(v + 8), v12 = load2(v + 10);  // column 1
  const Double2 v20 = load2(v + 12), v21 = load2(v + 14), v22 = load2(v + 16);
  const double* w = W.data();
  for (int c = 0; c < 6; ++c, S += stride) {
    // Column c of V W^T = V (row c of W)^T.
    const Double2 w0 = splat(w[c]), w1 = splat(w[6 + c]), w2 = splat(w[12 + c]);
    store2(S, load2(S) - (v00 * w0 + v10 * w1 + v20 * w2));
    store2(S + 2, load2(S + 2) - (v01 * w0 + v11 * w1 + v21 * w2));
    store2(S + 4, load2(S + 4) - (v02 * w0 + v12 * w1 + v22 * w2));
  }
}

// The same on a diagonal block, lower triangle only (all the Cholesky of S reads): column c gets
// the row pairs from (c & ~1) down, 12 of the 18 pairs. The entries it writes are computed exactly
// as subtractVWt computes them, so the factor and everything after it are bit-identical.
inline void subtractVWtLower(const Matrix63d& V, const Matrix63d& W, double* S, Eigen::Index stride) {
  using namespace schur_detail;
  const double* v = V.data();
  const Double2 v00 = load2(v), v01 = load2(v + 2), v02 = load2(v + 4);
  const Double2 v10 = load2(v + 6), v11 = load2(v + 8), v12 = load2(v + 10);
  const Double2 v20 = load2(v + 12), v21 = load2(v + 14), v22 = load2(v + 16);
  const double* w = W.data();
  for (int c = 0; c < 6; ++c, S += stride) {
    const Double2 w0 = splat(w[c]), w1 = splat(w[6 + c]), w2 = splat(w[12 + c]);
    if (c < 2) store2(S, load2(S) - (v00 * w0 + v10 * w1 + v20 * w2));
    if (c < 4) store2(S + 2, load2(S + 2) - (v01 * w0 + v11 * w1 + v21 * w2));
    store2(S + 4, load2(S + 4) - (v02 * w0 + v12 * w1 + v22 * w2));
  }
}

// S_block -= gamma x y^T (x, y: 6 doubles), the rank-one form of V W^T for line samples.
inline void subtractScaledOuter(double gamma, const double* x, const double* y, double* S, Eigen::Index stride) {
  using namespace schur_detail;
  const Double2 x0 = load2(x), x1 = load2(x + 2), x2 = load2(x + 4);
  for (int c = 0; c < 6; ++c, S += stride) {
    const Double2 s = splat(gamma * y[c]);
    store2(S, load2(S) - x0 * s);
    store2(S + 2, load2(S + 2) - x1 * s);
    store2(S + 4, load2(S + 4) - x2 * s);
  }
}

// The same on a diagonal block, lower triangle only (row pairs from (c & ~1) down, as
// subtractVWtLower).
inline void subtractScaledOuterLower(double gamma, const double* x, const double* y, double* S, Eigen::Index stride) {
  using namespace schur_detail;
  const Double2 x0 = load2(x), x1 = load2(x + 2), x2 = load2(x + 4);
  for (int c = 0; c < 6; ++c, S += stride) {
    const Double2 s = splat(gamma * y[c]);
    if (c < 2) store2(S, load2(S) - x0 * s);
    if (c < 4) store2(S + 2, load2(S + 2) - x1 * s);
    store2(S + 4, load2(S + 4) - x2 * s);
  }
}

// A run of rank-one updates of one 6x6 block, S_block -= gamma[l] x_l y_l^T for l = 0 .. count-1
// in that order, with x_l = u[l * step + x_index] and y_l = u[l * step + y_index] (6 doubles each).
// Every entry gets the subtractions subtractScaledOuter would give it, in the same order, so the
// block is bit-identical to `count` calls of it; but the block stays in registers, half of it (9
// 2-double vectors) at a time, instead of 18 loads and stores per update (issue 22, map stage).
inline void subtractScaledOuterRun(int count, const double* gamma, const double* const* u, int step, int x_index,
                                   int y_index, double* S, Eigen::Index stride) {
  using namespace schur_detail;
  for (int half = 0; half < 2; ++half) {
    double* const s0 = S + 3 * half * stride;
    double* const s1 = s0 + stride;
    double* const s2 = s1 + stride;
    Double2 a0 = load2(s0), a1 = load2(s0 + 2), a2 = load2(s0 + 4);
    Double2 b0 = load2(s1), b1 = load2(s1 + 2), b2 = load2(s1 + 4);
    Double2 c0 = load2(s2), c1 = load2(s2 + 2), c2 = load2(s2 + 4);
    for (int l = 0; l < count; ++l) {
      const double* const x = u[l * step + x_index];
      const double* const y = u[l * step + y_index] + 3 * half;
      const double g = gamma[l];
      const Double2 x0 = load2(x), x1 = load2(x + 2), x2 = load2(x + 4);
      const Double2 ta = splat(g * y[0]);
      a0 = a0 - x0 * ta;
      a1 = a1 - x1 * ta;
      a2 = a2 - x2 * ta;
      const Double2 tb = splat(g * y[1]);
      b0 = b0 - x0 * tb;
      b1 = b1 - x1 * tb;
      b2 = b2 - x2 * tb;
      const Double2 tc = splat(g * y[2]);
      c0 = c0 - x0 * tc;
      c1 = c1 - x1 * tc;
      c2 = c2 - x2 * tc;
    }
    store2(s0, a0), store2(s0 + 2, a1), store2(s0 + 4, a2);
    store2(s1, b0), store2(s1 + 2, b1), store2(s1 + 4, b2);
    store2(s2, c0), store2(s2 + 2, c1), store2(s2 + 4, c2);
  }
}

// The same on a diagonal block with x_l = y_l = u[l * step + index], lower triangle only: the
// entries subtractScaledOuterLower writes (column c from row pair (c & ~1) down, 12 vectors),
// all in registers at once.
inline void subtractScaledOuterLowerRun(int count, const double* gamma, const double* const* u, int step, int index,
                                        double* S, Eigen::Index stride) {
  using namespace schur_detail;
  double* const s0 = S;
  double* const s1 = s0 + stride;
  double* const s2 = s1 + stride;
  double* const s3 = s2 + stride;
  double* const s4 = s3 + stride;
  double* const s5 = s4 + stride;
  Double2 a0 = load2(s0), a1 = load2(s0 + 2), a2 = load2(s0 + 4);
  Double2 b0 = load2(s1), b1 = load2(s1 + 2), b2 = load2(s1 + 4);
  Double2 c1 = load2(s2 + 2), c2 = load2(s2 + 4);
  Double2 d1 = load2(s3 + 2), d2 = load2(s3 + 4);
  Double2 e2 = load2(s4 + 4);
  Double2 f2 = load2(s5 + 4);
  for (int l = 0; l < count; ++l) {
    const double* const x = u[l * step + index];
    const double g = gamma[l];
    const Double2 x0 = load2(x), x1 = load2(x + 2), x2 = load2(x + 4);
    const Double2 ta = splat(g * x[0]);
    a0 = a0 - x0 * ta;
    a1 = a1 - x1 * ta;
    a2 = a2 - x2 * ta;
    const Double2 tb = splat(g * x[1]);
    b0 = b0 - x0 * tb;
    b1 = b1 - x1 * tb;
    b2 = b2 - x2 * tb;
    const Double2 tc = splat(g * x[2]);
    c1 = c1 - x1 * tc;
    c2 = c2 - x2 * tc;
    const Double2 td = splat(g * x[3]);
    d1 = d1 - x1 * td;
    d2 = d2 - x2 * td;
    e2 = e2 - x2 * splat(g * x[4]);
    f2 = f2 - x2 * splat(g * x[5]);
  }
  store2(s0, a0), store2(s0 + 2, a1), store2(s0 + 4, a2);
  store2(s1, b0), store2(s1 + 2, b1), store2(s1 + 4, b2);
  store2(s2 + 2, c1), store2(s2 + 4, c2);
  store2(s3 + 2, d1), store2(s3 + 4, d2);
  store2(s4 + 4, e2);
  store2(s5 + 4, f2);
}

// V = W H (W 6x3, H 3x3) and rhs += V g (rhs: 6 doubles).
inline void formVAndRhs(const Matrix63d& W, const Eigen::Matrix3d& H, const Eigen::Vector3d& g, Matrix63d* V,
                        double* rhs) {
  using namespace schur_detail;
  const double* w = W.data();
  const Double2 w00 = load2(w), w01 = load2(w + 2), w02 = load2(w + 4);
  const Double2 w10 = load2(w + 6), w11 = load2(w + 8), w12 = load2(w + 10);
  const Double2 w20 = load2(w + 12), w21 = load2(w + 14), w22 = load2(w + 16);
  double* v = V->data();
  Double2 r0 = load2(rhs), r1 = load2(rhs + 2), r2 = load2(rhs + 4);
  for (int k = 0; k < 3; ++k) {
    const Double2 h0 = splat(H(0, k)), h1 = splat(H(1, k)), h2 = splat(H(2, k));
    const Double2 c0 = w00 * h0 + w10 * h1 + w20 * h2;
    const Double2 c1 = w01 * h0 + w11 * h1 + w21 * h2;
    const Double2 c2 = w02 * h0 + w12 * h1 + w22 * h2;
    store2(v + 6 * k, c0);
    store2(v + 6 * k + 2, c1);
    store2(v + 6 * k + 4, c2);
    const Double2 gk = splat(g(k));
    r0 += c0 * gk;
    r1 += c1 * gk;
    r2 += c2 * gk;
  }
  store2(rhs, r0);
  store2(rhs + 2, r1);
  store2(rhs + 4, r2);
}

}  // namespace plumb
