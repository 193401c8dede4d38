#pragma once
// Normal-equation blocks of one observation formed in camera-point space, shared by pose-only
// optimisation (pose_optimizer.cpp) and local BA (local_ba_linearization.cpp).
//
// Every factor's residual depends on the pose and the landmark only through
// P_cam = R P_world + t, so with J_cam = d e / d P_cam (R x 3), the pose Jacobian is J_cam A,
// A = d P_cam / d delta = [I | -[P_cam]x], and the landmark Jacobian is J_cam R. Everything the
// normal equations need follows from the 3x3 M = J_cam^T (w Omega) J_cam and q = J_cam^T (w Omega) e:
//   pose block      A^T M A = [ M  N ; N^T  [P]x N ],  N = M (-[P]x)      gradient A^T q = [ q ; P x q ]
//   landmark block  R^T M R                                               gradient R^T q
//   coupling W      A^T M R = [ M R ; [P]x M R ]
// which is about half the flops of forming the R x 6 and R x 3 Jacobians and their products.
#include <Eigen/Core>

#include "solver/schur_kernels.h"
#include "solver/types.h"

namespace plumb {

// Sums A^T M A and A^T q over observations: the upper triangle of the 6x6 sum, packed by columns
// into pairs of rows on 2-double vectors (schur_kernels.h's Double2: SSE2 on x86-64, NEON on
// aarch64), 12 pairs and 3 for the gradient:
//   column 0: h[0] = (0, 1*)   column 1: h[1] = (0, 1)   column 2: h[2] = (0, 1), h[3] = (2, 3*)
//   column 3: h[4] = (0, 1), h[5] = (2, 3)    column 4: h[6] = (0, 1), h[7] = (2, 3), h[8] = (4, 5*)
//   column 5: h[9] = (0, 1), h[10] = (2, 3), h[11] = (4, 5)        (* a lower entry, never read)
// Every entry of the upper triangle is the same product or difference, added in the same order,
// as in the scalar form this replaced (kept as the reference in tests/solver/schur_kernels_test.cpp,
// which compares the two bit for bit), so results are unchanged; it runs for every observation of
// every pose-only and local-BA linearisation, and the pairs halve the multiplies and additions and
// the loads and stores of the sums (27 scalars were kept in memory).
class PoseNormalAccumulator {
 public:
  void add(const Eigen::Matrix3d& M, const Eigen::Vector3d& q, const Eigen::Vector3d& P) {
    using namespace schur_detail;
    const double x = P.x(), y = P.y(), z = P.z();
    // The upper triangle of M by columns: (m00, *), (m01, m11), (m02, m12), m22 (element reads, not
    // vector loads, so that an M the caller has in registers is not stored first).
    const double m00 = M(0, 0), m01 = M(0, 1), m02 = M(0, 2), m11 = M(1, 1), m12 = M(1, 2), m22 = M(2, 2);
    const Double2 c0 = Double2{m00, 0.0}, c1 = Double2{m01, m11}, c2 = Double2{m02, m12};
    // N = M (-[P]x), by columns of its rows 0 and 1: n.0 = y m.2 - z m.1, n.1 = z m.0 - x m.2,
    // n.2 = x m.1 - y m.0 (the upper entries of M: m10 read as m01); row 2 as scalars.
    const Double2 r0_01 = Double2{m00, m01};
    const Double2 n0 = splat(y) * c2 - splat(z) * c1;     // (n00, n10)
    const Double2 n1 = splat(z) * r0_01 - splat(x) * c2;  // (n01, n11)
    const Double2 n2 = splat(x) * c1 - splat(y) * r0_01;  // (n02, n12)
    const double n20 = y * m22 - z * m12, n21 = z * m02 - x * m22, n22 = x * m12 - y * m02;
    // [P]x N, upper triangle: row 0 = y N_2. - z N_1., row 1 = z N_0. - x N_2., row 2 = x N_1. - y N_0.
    const Double2 rr01 = splat(y) * Double2{n20, n21} - splat(z) * Double2{n0[1], n1[1]};  // (rr00, rr01)
    const double rr02 = y * n22 - z * n2[1];
    const double rr11 = z * n1[0] - x * n21;
    const Double2 rr12_22 = Double2{z, x} * n2 - Double2{x, y} * Double2{n22, n2[0]};  // (rr12, rr22)
    h_[0] += c0, h_[1] += c1, h_[2] += c2, h_[3] += Double2{m22, 0.0};
    h_[4] += n0, h_[5] += Double2{n20, rr01[0]};
    h_[6] += n1, h_[7] += Double2{n21, rr01[1]}, h_[8] += Double2{rr11, 0.0};
    h_[9] += n2, h_[10] += Double2{n22, rr02}, h_[11] += rr12_22;
    // A^T q = (q, P x q).
    const double qx = q.x(), qy = q.y(), qz = q.z();
    g_[0] += Double2{qx, qy};
    g_[1] += Double2{qz, y * qz - z * qy};
    g_[2] += Double2{z, x} * Double2{qx, qy} - Double2{x, y} * Double2{qz, qx};
  }
  // The same for a rank-one A^T M A = u v^T (u = c v, so the product is symmetric) and A^T q = g:
  // column j gets the row pairs of u times v_j.
  void addRankOne(const Vector6d& u, const Vector6d& v, const Vector6d& g) {
    using namespace schur_detail;
    const Double2 u01 = load2(u.data()), u23 = load2(u.data() + 2), u45 = load2(u.data() + 4);
    const double* w = v.data();
    h_[0] += u01 * splat(w[0]);
    h_[1] += u01 * splat(w[1]);
    const Double2 v2 = splat(w[2]), v3 = splat(w[3]), v4 = splat(w[4]), v5 = splat(w[5]);
    h_[2] += u01 * v2, h_[3] += u23 * v2;
    h_[4] += u01 * v3, h_[5] += u23 * v3;
    h_[6] += u01 * v4, h_[7] += u23 * v4, h_[8] += u45 * v4;
    h_[9] += u01 * v5, h_[10] += u23 * v5, h_[11] += u45 * v5;
    g_[0] += load2(g.data()), g_[1] += load2(g.data() + 2), g_[2] += load2(g.data() + 4);
  }
  // Adds (sign 1) or removes (sign -1) another accumulator's sums.
  void merge(const PoseNormalAccumulator& other, double sign) {
    const schur_detail::Double2 s = schur_detail::splat(sign);
    for (int i = 0; i < 12; ++i) h_[i] += s * other.h_[i];
    for (int i = 0; i < 3; ++i) g_[i] += s * other.g_[i];
  }
  void finish(Matrix6d* H, Vector6d* g) const {
    // Entry (r, c), r <= c, is lane r % 2 of pair kColumnStart[c] + r / 2; the rest mirrored.
    static constexpr int kColumnStart[6] = {0, 1, 2, 4, 6, 9};
    for (int c = 0; c < 6; ++c) {
      for (int r = 0; r <= c; ++r) (*H)(r, c) = (*H)(c, r) = h_[kColumnStart[c] + r / 2][r % 2];
    }
    for (int i = 0; i < 6; ++i) (*g)(i) = g_[i / 2][i % 2];
  }

 private:
  schur_detail::Double2 h_[12] = {};  // upper triangle of H, column pairs (see the top)
  schur_detail::Double2 g_[3] = {};
};

// M = J_cam^T W J_cam and q = J_cam^T W e, by columns: GCC at -O2 does not inline Eigen's small
// product kernels, and this runs once per observation and iteration.
template <int R>
inline void pointSpaceBlocks(const Eigen::Matrix<double, R, 3>& J_cam, const Eigen::Matrix<double, R, R>& W,
                             const Eigen::Matrix<double, R, 1>& e, Eigen::Matrix3d* M, Eigen::Vector3d* q) {
  Eigen::Matrix<double, R, 3> WJ;
  for (int j = 0; j < 3; ++j) {
    WJ.col(j) = W.col(0) * J_cam(0, j);
    for (int r = 1; r < R; ++r) WJ.col(j) += W.col(r) * J_cam(r, j);
  }
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) (*M)(i, j) = J_cam.col(i).dot(WJ.col(j));
    (*q)(j) = WJ.col(j).dot(e);
  }
}

// The same for the stereo Jacobian of factors.h, J_cam = [fx/Z 0 j02; 0 fy/Z j12; fx/Z 0 j22]
// (rows u, v, u_r), using its zeros and M's symmetry and applying the IRLS weight once at the
// end: about half the instructions of the general form (it runs for most observations of every
// pose-only and local-BA iteration). `omega_e` = Omega e (the caller has it from chi2 = e^T Omega e).
inline void stereoPointSpaceBlocks(const Eigen::Matrix3d& J_cam, const Eigen::Matrix3d& omega,
                                   const Eigen::Vector3d& omega_e, double weight, Eigen::Matrix3d* M,
                                   Eigen::Vector3d* q) {
  const double a = J_cam(0, 0), c = J_cam(1, 1), j02 = J_cam(0, 2), j12 = J_cam(1, 2), j22 = J_cam(2, 2);
  // Omega J by columns: a (O0 + O2), c O1, j02 O0 + j12 O1 + j22 O2 (O_k: column k of Omega).
  const Eigen::Vector3d oj0 = a * (omega.col(0) + omega.col(2));
  const Eigen::Vector3d oj1 = c * omega.col(1);
  const Eigen::Vector3d oj2 = j02 * omega.col(0) + j12 * omega.col(1) + j22 * omega.col(2);
  // J^T x = (a (x0 + x2), c x1, j02 x0 + j12 x1 + j22 x2).
  const double m00 = a * (oj0(0) + oj0(2)), m01 = a * (oj1(0) + oj1(2)), m02 = a * (oj2(0) + oj2(2));
  const double m11 = c * oj1(1), m12 = c * oj2(1);
  const double m22 = j02 * oj2(0) + j12 * oj2(1) + j22 * oj2(2);
  *M << weight * m00, weight * m01, weight * m02,  //
      weight * m01, weight * m11, weight * m12,    //
      weight * m02, weight * m12, weight * m22;
  *q << weight * a * (omega_e(0) + omega_e(2)), weight * c * omega_e(1),
      weight * (j02 * omega_e(0) + j12 * omega_e(1) + j22 * omega_e(2));
}

}  // namespace plumb
