// Frame change and covariance conversion of drivers/mavlink/odometry_frames.h, against finite
// differences through expSE3 and the Euler conversion, and against the axis meanings of FRD.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "drivers/mavlink/odometry_frames.h"
#include "solver/se3.h"

namespace plumb {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Isometry3d makePose(const Eigen::Vector3d& rotation_vector, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expSO3(rotation_vector);
  T.translation() = t;
  return T;
}

double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// [x y z roll pitch yaw] of the body after the solver's perturbation of T_cam_world.
Vector6d mavlinkState(const Vector6d& delta, const Eigen::Isometry3d& T_world_cam,
                      const MavlinkFrameChange& frames) {
  const Eigen::Isometry3d T_cam_world = applyLeftIncrement(delta, T_world_cam.inverse());
  const Eigen::Isometry3d T_local_body = localBodyPose(T_cam_world.inverse(), frames);
  Vector6d s;
  s << T_local_body.translation(), eulerRollPitchYaw(T_local_body.linear());
  return s;
}

Matrix6d numericJacobian(const Eigen::Isometry3d& T_world_cam, const MavlinkFrameChange& frames) {
  constexpr double h = 1e-6;
  Matrix6d J;
  for (int i = 0; i < 6; ++i) {
    Vector6d d = Vector6d::Zero();
    d(i) = h;
    Vector6d diff = mavlinkState(d, T_world_cam, frames) - mavlinkState(-d, T_world_cam, frames);
    for (int k = 3; k < 6; ++k) diff(k) = wrapAngle(diff(k));
    J.col(i) = diff / (2 * h);
  }
  return J;
}

TEST(MavlinkFrames, EulerAnglesRoundTrip) {
  const Eigen::Vector3d rpy(0.3, -0.7, 2.5);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  EXPECT_TRUE(eulerRollPitchYaw(R).isApprox(rpy, 1e-12));
}

TEST(MavlinkFrames, CameraMotionMapsToFrdAxes) {
  const MavlinkFrameChange frames;  // forward camera, local = body at the world origin
  // At the world origin the body is at the local origin, level, heading 0.
  const Eigen::Isometry3d T0 = localBodyPose(Eigen::Isometry3d::Identity(), frames);
  EXPECT_TRUE(T0.isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  // Camera 1 m along its optical axis (world z) = 1 m forward (local x); world y (down) = local z.
  EXPECT_TRUE(localBodyPose(makePose(Eigen::Vector3d::Zero(), {0, 0, 1}), frames)
                  .translation()
                  .isApprox(Eigen::Vector3d(1, 0, 0), 1e-12));
  EXPECT_TRUE(localBodyPose(makePose(Eigen::Vector3d::Zero(), {0, 1, 0}), frames)
                  .translation()
                  .isApprox(Eigen::Vector3d(0, 0, 1), 1e-12));
  EXPECT_TRUE(localBodyPose(makePose(Eigen::Vector3d::Zero(), {1, 0, 0}), frames)
                  .translation()
                  .isApprox(Eigen::Vector3d(0, 1, 0), 1e-12));
  // Turning right = rotating about the camera's down axis (y) by +a: yaw +a.
  const double a = 0.4;
  Eigen::Vector3d rpy = eulerRollPitchYaw(localBodyPose(makePose({0, a, 0}, {0, 0, 0}), frames).linear());
  EXPECT_TRUE(rpy.isApprox(Eigen::Vector3d(0, 0, a), 1e-12)) << rpy.transpose();
  // Nose up = rotating about the camera's right axis (x) by +a (z swings toward -y, up): pitch +a.
  rpy = eulerRollPitchYaw(localBodyPose(makePose({a, 0, 0}, {0, 0, 0}), frames).linear());
  EXPECT_TRUE(rpy.isApprox(Eigen::Vector3d(0, a, 0), 1e-12)) << rpy.transpose();
  // Right wing down = rotating about the optical axis (z) by +a: roll +a.
  rpy = eulerRollPitchYaw(localBodyPose(makePose({0, 0, a}, {0, 0, 0}), frames).linear());
  EXPECT_TRUE(rpy.isApprox(Eigen::Vector3d(a, 0, 0), 1e-12)) << rpy.transpose();
}

TEST(MavlinkFrames, MountedCameraStartsAtLocalOrigin) {
  MavlinkFrameChange frames;
  // Camera 0.1 m forward and 0.05 m below the body origin, tilted 20 degrees down.
  frames.T_body_cam = forwardCameraBodyFrdExtrinsic();
  frames.T_body_cam.translation() = Eigen::Vector3d(0.1, 0.0, 0.05);
  frames.T_body_cam.linear() =
      Eigen::AngleAxisd(-20 * kPi / 180, Eigen::Vector3d::UnitY()).toRotationMatrix() *
      frames.T_body_cam.linear();
  frames.T_local_world = frames.T_body_cam;
  EXPECT_TRUE(
      localBodyPose(Eigen::Isometry3d::Identity(), frames).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
}

TEST(MavlinkCovariance, JacobianMatchesFiniteDifferences) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    MavlinkFrameChange frames;
    if (trial % 2 == 1) {  // a non-trivial mounting: rotated and offset
      frames.T_body_cam =
          makePose({0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng)}, {0.2 * u(rng), 0.2 * u(rng), 0.2 * u(rng)}) *
          forwardCameraBodyFrdExtrinsic();
      frames.T_local_world = frames.T_body_cam;
    }
    const Eigen::Isometry3d T_world_cam =
        makePose({0.6 * u(rng), 0.6 * u(rng), 0.6 * u(rng)}, {3 * u(rng), 3 * u(rng), 3 * u(rng)});
    const Matrix6d J = mavlinkPoseJacobian(T_world_cam, frames);
    const Matrix6d J_numeric = numericJacobian(T_world_cam, frames);
    EXPECT_LT((J - J_numeric).cwiseAbs().maxCoeff(), 1e-6) << "trial " << trial << "\nanalytic\n"
                                                           << J << "\nnumeric\n"
                                                           << J_numeric;

    // The propagated covariance is J Sigma J^T with the numeric J.
    Matrix6d A;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) A(r, c) = 0.01 * u(rng);
    const Matrix6d sigma = A * A.transpose() + 1e-6 * Matrix6d::Identity();
    const Matrix6d expected = J_numeric * sigma * J_numeric.transpose();
    const Matrix6d got = mavlinkPoseCovariance(sigma, T_world_cam, frames);
    EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-9 + 1e-5 * expected.cwiseAbs().maxCoeff());
    EXPECT_TRUE(got.isApprox(got.transpose(), 1e-12));
  }
}

TEST(MavlinkCovariance, PureRotationUncertaintyShowsAsYaw) {
  // Uncertainty only about the camera's down axis (phi_y) at the origin is yaw uncertainty only.
  const MavlinkFrameChange frames;
  Matrix6d sigma = Matrix6d::Zero();
  sigma(4, 4) = 0.01;
  const Matrix6d s = mavlinkPoseCovariance(sigma, Eigen::Isometry3d::Identity(), frames);
  EXPECT_NEAR(s(5, 5), 0.01, 1e-15);
  EXPECT_NEAR(s.norm(), 0.01, 1e-15);
}

TEST(MavlinkCovariance, UpperTriangleIsRowMajor) {
  Matrix6d m;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) m(r, c) = 10 * r + c;
  float out[21];
  upperTriangle21(m, out);
  EXPECT_EQ(out[0], 0.f);    // (0,0)
  EXPECT_EQ(out[5], 5.f);    // (0,5)
  EXPECT_EQ(out[6], 11.f);   // (1,1)
  EXPECT_EQ(out[11], 22.f);  // (2,2)
  EXPECT_EQ(out[20], 55.f);  // (5,5)
}

}  // namespace
}  // namespace plumb

namespace plumb {
namespace {

// The velocity covariance (odometry_frames.h) against sampling: two consecutive poses perturbed by
// independent errors from their map-relative covariances, the velocity computed exactly as the
// sink sends it (body frame, differenced over dt), its sample covariance vs the formula.
TEST(MavlinkFrames, VelocityCovarianceMatchesSampling) {
  std::mt19937 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  MavlinkFrameChange frames;
  frames.T_body_cam.translation() = Eigen::Vector3d(0.4, -0.1, 0.2);  // a lever arm
  const Eigen::Isometry3d T_world_cam_previous = makePose(Eigen::Vector3d(0.2, -0.4, 0.1), Eigen::Vector3d(0.5, 0.2, 1.0));
  const Eigen::Isometry3d T_world_cam = T_world_cam_previous * makePose(Eigen::Vector3d(0.01, 0.015, -0.005),
                                                                    Eigen::Vector3d(0.02, -0.01, 0.03));
  const double dt = 1.0 / 30.0;
  Matrix6d A = Matrix6d::Zero(), B = Matrix6d::Zero();
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) {
      A(r, c) = n(rng);
      B(r, c) = n(rng);
    }
  const Matrix6d L_previous = 1e-6 * (A * A.transpose() / 6 + 0.2 * Matrix6d::Identity());
  const Matrix6d L = 1e-6 * (B * B.transpose() / 6 + 0.2 * Matrix6d::Identity());
  const Matrix6d chol_previous = L_previous.llt().matrixL(), chol = L.llt().matrixL();
  auto velocity = [&](const Eigen::Isometry3d& previous, const Eigen::Isometry3d& current) {
    const Eigen::Isometry3d P = localBodyPose(previous, frames), C = localBodyPose(current, frames);
    Vector6d v;
    v << C.linear().transpose() * (C.translation() - P.translation()) / dt,
        logSO3(P.linear().transpose() * C.linear()) / dt;
    return v;
  };
  const Vector6d v0 = velocity(T_world_cam_previous, T_world_cam);
  const int samples = 40000;
  Matrix6d sum = Matrix6d::Zero();
  for (int k = 0; k < samples; ++k) {
    Vector6d z0, z1;
    for (int i = 0; i < 6; ++i) {
      z0(i) = n(rng);
      z1(i) = n(rng);
    }
    const Eigen::Isometry3d previous = applyLeftIncrement(chol_previous * z0, T_world_cam_previous.inverse()).inverse();
    const Eigen::Isometry3d current = applyLeftIncrement(chol * z1, T_world_cam.inverse()).inverse();
    const Vector6d dv = velocity(previous, current) - v0;
    sum += dv * dv.transpose();
  }
  const Matrix6d sampled = sum / samples;
  const Matrix6d predicted = mavlinkVelocityCovariance(L_previous, L, T_world_cam_previous, T_world_cam, dt, frames);
  EXPECT_LT((sampled - predicted).norm(), 0.04 * predicted.norm()) << "sampled\n" << sampled << "\npredicted\n" << predicted;
  // Ignoring the lever arm (the adjoint) would be visibly wrong.
  MavlinkFrameChange no_lever = frames;
  no_lever.T_body_cam.translation().setZero();
  const Matrix6d wrong = mavlinkVelocityCovariance(L_previous, L, T_world_cam_previous, T_world_cam, dt, no_lever);
  EXPECT_GT((sampled - wrong).norm(), 0.1 * predicted.norm());
}

}  // namespace
}  // namespace plumb
