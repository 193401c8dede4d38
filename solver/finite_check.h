#pragma once
// Whether every value of an array is finite, answered as Eigen's allFinite() answers it (x - x is
// +0 for a finite x and NaN otherwise), but summed on 2-double vectors with one test at the end:
// a NaN anywhere makes the sum NaN, +0s sum to +0. Eigen's form tests every entry with a compare
// and a branch (about 4 instructions each); the local BA checks every observation it is given and
// every landmark block it inverts (issue 22). Same answer for every input
// (tests/solver/schur_kernels_test.cpp).
#include <Eigen/Core>

#include "solver/schur_kernels.h"

namespace plumb {

inline double finiteResidue(const double* x, Eigen::Index n) {
  using namespace schur_detail;
  Double2 sum = {0.0, 0.0};
  Eigen::Index i = 0;
  for (; i + 2 <= n; i += 2) {
    const Double2 v = load2(x + i);
    sum += v - v;
  }
  double s = sum[0] + sum[1];
  if (i < n) s += x[i] - x[i];
  return s;  // +0 when all are finite, NaN otherwise
}

inline bool allFiniteValues(const double* x, Eigen::Index n) {
  const double s = finiteResidue(x, n);
  return s == s;
}

// A fixed-size matrix or vector (contiguous storage).
template <typename Derived>
inline bool allFiniteValues(const Eigen::PlainObjectBase<Derived>& m) {
  return allFiniteValues(m.data(), m.size());
}

}  // namespace plumb
