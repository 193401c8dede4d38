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

#include "solver/types.h"

namespace plumb {

// Sums A^T M A and A^T q over observations, on scalars of the symmetric halves.
class PoseNormalAccumulator {
 public:
  void add(const Eigen::Matrix3d& M, const Eigen::Vector3d& q, const Eigen::Vector3d& P) {
    const double x = P.x(), y = P.y(), z = P.z();
    const double m00 = M(0, 0), m01 = M(0, 1), m02 = M(0, 2), m11 = M(1, 1), m12 = M(1, 2), m22 = M(2, 2);
    // N = M (-[P]x); the columns of -[P]x are (0, -z, y), (z, 0, -x), (-y, x, 0).
    const double n00 = y * m02 - z * m01, n01 = z * m00 - x * m02, n02 = x * m01 - y * m00;
    const double n10 = y * m12 - z * m11, n11 = z * m01 - x * m12, n12 = x * m11 - y * m01;
    const double n20 = y * m22 - z * m12, n21 = z * m02 - x * m22, n22 = x * m12 - y * m02;
    tt_[0] += m00, tt_[1] += m01, tt_[2] += m02, tt_[3] += m11, tt_[4] += m12, tt_[5] += m22;
    tr_[0] += n00, tr_[1] += n01, tr_[2] += n02;
    tr_[3] += n10, tr_[4] += n11, tr_[5] += n12;
    tr_[6] += n20, tr_[7] += n21, tr_[8] += n22;
    // [P]x N, upper triangle: row 0 = y N_2. - z N_1., row 1 = z N_0. - x N_2., row 2 = x N_1. - y N_0.
    rr_[0] += y * n20 - z * n10, rr_[1] += y * n21 - z * n11, rr_[2] += y * n22 - z * n12;
    rr_[3] += z * n01 - x * n21, rr_[4] += z * n02 - x * n22;
    rr_[5] += x * n12 - y * n02;
    g_[0] += q.x(), g_[1] += q.y(), g_[2] += q.z();
    g_[3] += y * q.z() - z * q.y(), g_[4] += z * q.x() - x * q.z(), g_[5] += x * q.y() - y * q.x();
  }
  // The same for a rank-one A^T M A = u v^T (u = c v, so the product is symmetric) and A^T q = g.
  void addRankOne(const Vector6d& u, const Vector6d& v, const Vector6d& g) {
    tt_[0] += u(0) * v(0), tt_[1] += u(0) * v(1), tt_[2] += u(0) * v(2);
    tt_[3] += u(1) * v(1), tt_[4] += u(1) * v(2), tt_[5] += u(2) * v(2);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) tr_[3 * r + c] += u(r) * v(3 + c);
    }
    rr_[0] += u(3) * v(3), rr_[1] += u(3) * v(4), rr_[2] += u(3) * v(5);
    rr_[3] += u(4) * v(4), rr_[4] += u(4) * v(5), rr_[5] += u(5) * v(5);
    for (int i = 0; i < 6; ++i) g_[i] += g(i);
  }
  // Adds (sign 1) or removes (sign -1) another accumulator's sums.
  void merge(const PoseNormalAccumulator& other, double sign) {
    for (int i = 0; i < 6; ++i) tt_[i] += sign * other.tt_[i], rr_[i] += sign * other.rr_[i], g_[i] += sign * other.g_[i];
    for (int i = 0; i < 9; ++i) tr_[i] += sign * other.tr_[i];
  }
  void finish(Matrix6d* H, Vector6d* g) const {
    *H << tt_[0], tt_[1], tt_[2], tr_[0], tr_[1], tr_[2],  //
        tt_[1], tt_[3], tt_[4], tr_[3], tr_[4], tr_[5],    //
        tt_[2], tt_[4], tt_[5], tr_[6], tr_[7], tr_[8],    //
        tr_[0], tr_[3], tr_[6], rr_[0], rr_[1], rr_[2],    //
        tr_[1], tr_[4], tr_[7], rr_[1], rr_[3], rr_[4],    //
        tr_[2], tr_[5], tr_[8], rr_[2], rr_[4], rr_[5];
    *g = Eigen::Map<const Vector6d>(g_);
  }

 private:
  double tt_[6] = {};  // upper triangle of the translation block
  double tr_[9] = {};  // translation-rotation block, row-major
  double rr_[6] = {};  // upper triangle of the rotation block
  double g_[6] = {};
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
