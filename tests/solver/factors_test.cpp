// Analytic Jacobians of every factor against central differences, for the pose (left
// perturbation) and the point blocks, at random well-conditioned configurations.
#include "solver/factors.h"

#include <random>

#include <gtest/gtest.h>

#include "solver/se3.h"

namespace plumb {
namespace {

constexpr double kStep = 1e-6;
constexpr double kMaxRelativeError = 1e-6;

struct FactorSetup {
  CameraIntrinsics camera;
  Eigen::Isometry3d T_cam_world;
  Eigen::Vector3d P_world;
};

FactorSetup randomSetup(std::mt19937& rng, double fy_sign) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  FactorSetup s;
  s.camera = {520.0 + 20.0 * u(rng), fy_sign * (515.0 + 20.0 * u(rng)), 320.0 + 5.0 * u(rng),
              240.0 + 5.0 * u(rng), 40.0};
  Vector6d xi;
  xi << 0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng), 0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng);
  s.T_cam_world = expSE3(xi);
  // A point 1-4 m in front of the camera, expressed in the world frame.
  const Eigen::Vector3d P_cam(0.8 * u(rng), 0.6 * u(rng), 2.5 + 1.5 * u(rng));
  s.P_world = s.T_cam_world.inverse() * P_cam;
  return s;
}

template <typename A, typename B>
double relativeError(const A& analytic, const B& numeric) {
  return (analytic - numeric).norm() / std::max(numeric.norm(), 1e-12);
}

// Central differences of a residual function r(T, P) with respect to the pose and the point.
template <int R, typename F>
void numericJacobians(const F& residual, const FactorSetup& s, Eigen::Matrix<double, R, 6>* J_pose,
                      Eigen::Matrix<double, R, 3>* J_point) {
  for (int k = 0; k < 6; ++k) {
    Vector6d d = Vector6d::Zero();
    d(k) = kStep;
    J_pose->col(k) = (residual(applyLeftIncrement(d, s.T_cam_world), s.P_world) -
                      residual(applyLeftIncrement(-d, s.T_cam_world), s.P_world)) /
                     (2.0 * kStep);
  }
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d(k) = kStep;
    J_point->col(k) = (residual(s.T_cam_world, s.P_world + d) - residual(s.T_cam_world, s.P_world - d)) / (2.0 * kStep);
  }
}

class FactorJacobians : public ::testing::TestWithParam<double> {};  // parameter: sign of fy

TEST_P(FactorJacobians, StereoPoint) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const FactorSetup s = randomSetup(rng, GetParam());
    const Eigen::Vector3d z(300.0, 200.0, 280.0);
    auto residual = [&](const Eigen::Isometry3d& T, const Eigen::Vector3d& P) {
      Eigen::Vector3d e;
      EXPECT_TRUE(evaluateStereoPoint(s.camera, T, P, z, &e, nullptr, nullptr));
      return e;
    };
    Eigen::Vector3d e;
    Matrix36d J_pose;
    Eigen::Matrix3d J_point;
    ASSERT_TRUE(evaluateStereoPoint(s.camera, s.T_cam_world, s.P_world, z, &e, &J_pose, &J_point));
    Matrix36d N_pose;
    Eigen::Matrix3d N_point;
    numericJacobians<3>(residual, s, &N_pose, &N_point);
    EXPECT_LT(relativeError(J_pose, N_pose), kMaxRelativeError) << trial;
    EXPECT_LT(relativeError(J_point, N_point), kMaxRelativeError) << trial;
    EXPECT_TRUE(e.isApprox(residual(s.T_cam_world, s.P_world)));
  }
}

TEST_P(FactorJacobians, MonoPoint) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 50; ++trial) {
    const FactorSetup s = randomSetup(rng, GetParam());
    const Eigen::Vector2d z(310.0, 250.0);
    auto residual = [&](const Eigen::Isometry3d& T, const Eigen::Vector3d& P) {
      Eigen::Vector2d e;
      EXPECT_TRUE(evaluateMonoPoint(s.camera, T, P, z, &e, nullptr, nullptr));
      return e;
    };
    Eigen::Vector2d e;
    Matrix26d J_pose;
    Matrix23d J_point;
    ASSERT_TRUE(evaluateMonoPoint(s.camera, s.T_cam_world, s.P_world, z, &e, &J_pose, &J_point));
    Matrix26d N_pose;
    Matrix23d N_point;
    numericJacobians<2>(residual, s, &N_pose, &N_point);
    EXPECT_LT(relativeError(J_pose, N_pose), kMaxRelativeError) << trial;
    EXPECT_LT(relativeError(J_point, N_point), kMaxRelativeError) << trial;
  }
}

TEST_P(FactorJacobians, LineSample) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const FactorSetup s = randomSetup(rng, GetParam());
    Eigen::Vector3d line;
    ASSERT_TRUE(normalizeLine(Eigen::Vector3d(u(rng), u(rng), 200.0 * u(rng)), &line));
    auto residual = [&](const Eigen::Isometry3d& T, const Eigen::Vector3d& P) {
      Eigen::Matrix<double, 1, 1> e;
      EXPECT_TRUE(evaluateLineSample(s.camera, T, P, line, &e(0), nullptr, nullptr));
      return e;
    };
    double e = 0.0;
    RowVector6d J_pose;
    Eigen::RowVector3d J_point;
    ASSERT_TRUE(evaluateLineSample(s.camera, s.T_cam_world, s.P_world, line, &e, &J_pose, &J_point));
    RowVector6d N_pose;
    Eigen::RowVector3d N_point;
    numericJacobians<1>(residual, s, &N_pose, &N_point);
    EXPECT_LT(relativeError(J_pose, N_pose), kMaxRelativeError) << trial;
    EXPECT_LT(relativeError(J_point, N_point), kMaxRelativeError) << trial;
  }
}

INSTANTIATE_TEST_SUITE_P(PositiveAndNegativeFy, FactorJacobians, ::testing::Values(1.0, -1.0));

TEST(Factors, StereoResidualIsPredictionMinusMeasurement) {
  const CameraIntrinsics camera{500.0, 500.0, 320.0, 240.0, 40.0};
  const Eigen::Vector3d P(0.2, -0.1, 2.0);
  Eigen::Vector3d e;
  ASSERT_TRUE(evaluateStereoPoint(camera, Eigen::Isometry3d::Identity(), P, Eigen::Vector3d::Zero(), &e, nullptr,
                                  nullptr));
  EXPECT_NEAR(e(0), 500.0 * 0.1 + 320.0, 1e-12);
  EXPECT_NEAR(e(1), -500.0 * 0.05 + 240.0, 1e-12);
  EXPECT_NEAR(e(2), e(0) - 40.0 / 2.0, 1e-12);
}

TEST(Factors, LineResidualIsSignedPixelDistance) {
  const CameraIntrinsics camera{500.0, 500.0, 320.0, 240.0, 40.0};
  Eigen::Vector3d line;
  ASSERT_TRUE(normalizeLine(Eigen::Vector3d(0.0, 2.0, -2.0 * 100.0), &line));  // v = 100
  double e = 0.0;
  // Point projecting to v = 240 (principal point row): 140 px below the line v = 100.
  ASSERT_TRUE(evaluateLineSample(camera, Eigen::Isometry3d::Identity(), Eigen::Vector3d(0.0, 0.0, 3.0), line, &e,
                                 nullptr, nullptr));
  EXPECT_NEAR(e, 140.0, 1e-12);
}

TEST(Factors, RejectPointsBehindOrAtTheCamera) {
  const CameraIntrinsics camera{500.0, 500.0, 320.0, 240.0, 40.0};
  Eigen::Vector3d e3(7.0, 7.0, 7.0);
  for (const Eigen::Vector3d& P : {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.1, 0.2, -1.0)}) {
    EXPECT_FALSE(evaluateStereoPoint(camera, Eigen::Isometry3d::Identity(), P, Eigen::Vector3d::Zero(), &e3,
                                     nullptr, nullptr));
    EXPECT_EQ(e3, Eigen::Vector3d(7.0, 7.0, 7.0));  // outputs untouched
  }
  Eigen::Vector3d line;
  EXPECT_FALSE(normalizeLine(Eigen::Vector3d(0.0, 0.0, 1.0), &line));
}

}  // namespace
}  // namespace plumb
