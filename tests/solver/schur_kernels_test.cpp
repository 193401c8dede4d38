// The fast paths of the solvers' inner loops against straightforward Eigen references written
// from their definitions: the stereo point-space blocks (solver/point_space_blocks.h), the pose
// block lifted from them, and the small kernels of the landmark elimination
// (solver/schur_kernels.h; its diagonal-block variant writes the lower triangle only). They
// compute the same sums in another order, so the comparisons are to a relative 1e-12, which any
// wrong index or sign misses by far.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "solver/factors.h"
#include "solver/finite_check.h"
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

// The scalar form PoseNormalAccumulator had before its sums were packed into 2-double vectors
// (issue 22, track pass): every entry as its own product or difference, 27 sums. The packed form
// must produce the same bits (same products, same order of addition), which is what keeps
// tracking's and local BA's output byte-identical.
class ScalarPoseNormalAccumulator {
 public:
  void add(const Eigen::Matrix3d& M, const Eigen::Vector3d& q, const Eigen::Vector3d& P) {
    const double x = P.x(), y = P.y(), z = P.z();
    const double m00 = M(0, 0), m01 = M(0, 1), m02 = M(0, 2), m11 = M(1, 1), m12 = M(1, 2), m22 = M(2, 2);
    const double n00 = y * m02 - z * m01, n01 = z * m00 - x * m02, n02 = x * m01 - y * m00;
    const double n10 = y * m12 - z * m11, n11 = z * m01 - x * m12, n12 = x * m11 - y * m01;
    const double n20 = y * m22 - z * m12, n21 = z * m02 - x * m22, n22 = x * m12 - y * m02;
    tt_[0] += m00, tt_[1] += m01, tt_[2] += m02, tt_[3] += m11, tt_[4] += m12, tt_[5] += m22;
    tr_[0] += n00, tr_[1] += n01, tr_[2] += n02;
    tr_[3] += n10, tr_[4] += n11, tr_[5] += n12;
    tr_[6] += n20, tr_[7] += n21, tr_[8] += n22;
    rr_[0] += y * n20 - z * n10, rr_[1] += y * n21 - z * n11, rr_[2] += y * n22 - z * n12;
    rr_[3] += z * n01 - x * n21, rr_[4] += z * n02 - x * n22;
    rr_[5] += x * n12 - y * n02;
    g_[0] += q.x(), g_[1] += q.y(), g_[2] += q.z();
    g_[3] += y * q.z() - z * q.y(), g_[4] += z * q.x() - x * q.z(), g_[5] += x * q.y() - y * q.x();
  }
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
  void merge(const ScalarPoseNormalAccumulator& other, double sign) {
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
  double tt_[6] = {}, tr_[9] = {}, rr_[6] = {}, g_[6] = {};
};

// Exactly equal where the compiler does not fuse a * b + c (x86-64 without -mfma); GCC on aarch64
// fuses by default and may do so differently in the scalar and the vector form, so there the
// comparison is to kTolerance.
void expectSameSums(const Matrix6d& H, const Vector6d& g, const Matrix6d& H_ref, const Vector6d& g_ref, int n) {
#if defined(__x86_64__) && !defined(__FMA__)
  for (int i = 0; i < 36; ++i) ASSERT_EQ(H(i), H_ref(i)) << n << " H(" << i % 6 << ", " << i / 6 << ")";
  for (int i = 0; i < 6; ++i) ASSERT_EQ(g(i), g_ref(i)) << n << " g(" << i << ")";
#else
  ASSERT_LT(relativeError(H, H_ref), kTolerance) << n;
  ASSERT_LT(relativeError(g, g_ref), kTolerance) << n;
#endif
}

TEST(SolverKernels, PoseNormalAccumulatorEqualsItsScalarFormBitForBit) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PoseNormalAccumulator packed, packed_other;
  ScalarPoseNormalAccumulator scalar, scalar_other;
  for (int n = 0; n < 300; ++n) {
    const Eigen::Vector3d P(3.0 * u(rng), 2.0 * u(rng), 2.0 + 1.5 * u(rng));
    const int kind = n % 3;
    if (kind < 2) {
      // An asymmetric M too (mono points' M is symmetric only up to rounding): the upper entries
      // are the ones read.
      Eigen::Matrix3d M = randomInformation(rng);
      if (kind == 1) M(1, 0) += 1e-3 * u(rng), M(2, 0) += 1e-3 * u(rng), M(2, 1) += 1e-3 * u(rng);
      const Eigen::Vector3d q(u(rng), u(rng), u(rng));
      packed.add(M, q, P);
      scalar.add(M, q, P);
      packed_other.add(M, -q, P);
      scalar_other.add(M, -q, P);
    } else {
      Vector6d v, g;
      for (int i = 0; i < 6; ++i) v(i) = u(rng), g(i) = u(rng);
      const Vector6d w = (0.5 + u(rng)) * v;
      packed.addRankOne(w, v, g);
      scalar.addRankOne(w, v, g);
    }
    if (n % 50 == 49) {  // removing and adding another accumulator's sums
      packed.merge(packed_other, n % 100 == 49 ? -1.0 : 1.0);
      scalar.merge(scalar_other, n % 100 == 49 ? -1.0 : 1.0);
    }
    Matrix6d H, H_ref;
    Vector6d g, g_ref;
    packed.finish(&H, &g);
    scalar.finish(&H_ref, &g_ref);
    expectSameSums(H, g, H_ref, g_ref, n);
    ASSERT_EQ((H - H.transpose()).cwiseAbs().maxCoeff(), 0.0) << n;
  }
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

// The run kernels (a line's samples written block by block, issue 22) against the single-update
// kernels they replace, called once per landmark in order: the same bits, not just close values
// (local BA's output must not change), and nothing outside the block or, for the diagonal block,
// outside the entries subtractScaledOuterLower writes.
void expectSameBits(const Eigen::MatrixXd& got, const Eigen::MatrixXd& expected, int trial) {
#if defined(__x86_64__) && !defined(__FMA__)
  for (Eigen::Index i = 0; i < got.size(); ++i) {
    ASSERT_EQ(std::memcmp(&got(i), &expected(i), sizeof(double)), 0) << trial << " " << i;
  }
#else  // (as DenseCholesky's test: where GCC fuses a - x * t, the two forms may fuse differently)
  ASSERT_LT((got - expected).norm(), 1e-12 * std::max(1.0, expected.norm())) << trial;
#endif
}

TEST(SolverKernels, RunKernelsEqualOneUpdateAtATimeBitForBit) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int count = 1 + trial % 32;
    const int width = 1 + trial % 5;  // observations per landmark: u[l * width + index]
    const Eigen::Index stride = 6 + trial % 7;
    std::vector<double> storage(static_cast<std::size_t>(count * width * 6));
    for (double& x : storage) x = unit(rng) * std::pow(10.0, 3.0 * unit(rng));
    std::vector<const double*> u(static_cast<std::size_t>(count * width));
    for (std::size_t i = 0; i < u.size(); ++i) u[i] = storage.data() + 6 * i;
    std::vector<double> gamma(static_cast<std::size_t>(count));
    for (double& g : gamma) g = unit(rng);
    const int x_index = trial % width, y_index = (trial / 3) % width;
    Eigen::MatrixXd start(stride, 8);
    for (Eigen::Index i = 0; i < start.size(); ++i) start(i) = unit(rng);

    Eigen::MatrixXd got = start, expected = start;
    subtractScaledOuterRun(count, gamma.data(), u.data(), width, x_index, y_index, got.data() + 1, stride);
    for (int l = 0; l < count; ++l) {
      subtractScaledOuter(gamma[l], u[l * width + x_index], u[l * width + y_index], expected.data() + 1, stride);
    }
    expectSameBits(got, expected, trial);
    ASSERT_NE(std::memcmp(got.data(), start.data(), sizeof(double) * got.size()), 0) << trial;

    Eigen::MatrixXd got_lower = start, expected_lower = start;
    subtractScaledOuterLowerRun(count, gamma.data(), u.data(), width, x_index, got_lower.data() + 1, stride);
    for (int l = 0; l < count; ++l) {
      const double* x = u[l * width + x_index];
      subtractScaledOuterLower(gamma[l], x, x, expected_lower.data() + 1, stride);
    }
    expectSameBits(got_lower, expected_lower, trial);
    ASSERT_NE(std::memcmp(got_lower.data(), start.data(), sizeof(double) * got_lower.size()), 0) << trial;
  }
}

TEST(SolverKernels, FiniteCheckAnswersAsEigenAllFinite) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double specials[] = {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::max(),
                             -std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min(), -0.0};
  int non_finite = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = 1 + trial % 13;
    Eigen::VectorXd x(n);
    for (int i = 0; i < n; ++i) x(i) = unit(rng) * 1e300;
    for (int k = 0; k < trial % 3; ++k) x(static_cast<int>(rng() % n)) = specials[rng() % 7];
    ASSERT_EQ(allFiniteValues(x.data(), n), x.allFinite()) << trial;
    non_finite += x.allFinite() ? 0 : 1;
  }
  EXPECT_GT(non_finite, 100);
  Eigen::Matrix3d H = Eigen::Matrix3d::Constant(std::numeric_limits<double>::max());
  EXPECT_TRUE(allFiniteValues(H));  // no overflow: the entries are not summed, x - x is
  H(2, 1) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(allFiniteValues(H));
}

}  // namespace
}  // namespace plumb
