#include "bench/solver/ceres_local_ba.h"

#include <chrono>
#include <ctime>
#include <memory>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>

#include "solver/factors.h"
#include "solver/se3.h"

namespace plumb::bench {
namespace {

// Pose block: [qx qy qz qw tx ty tz] of T_cam_world, updated by T <- exp(delta) T (solver/se3.h).
// Cost functions return their Jacobian in the 6-dof tangent space padded with a zero column,
// and PlusJacobian is [I_6; 0], the usual way to hand Ceres analytic tangent Jacobians.
class LeftSe3Manifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    const Eigen::Isometry3d T = toIsometry(x);
    const Eigen::Isometry3d T_new = applyLeftIncrement(Eigen::Map<const Vector6d>(delta), T);
    fromIsometry(T_new, x_plus_delta);
    return true;
  }
  bool PlusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.topRows<6>().setIdentity();
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<Vector6d> out(y_minus_x);
    out = logSE3(toIsometry(y) * toIsometry(x).inverse());
    return true;
  }
  bool MinusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.leftCols<6>().setIdentity();
    return true;
  }
  static Eigen::Isometry3d toIsometry(const double* x) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(x[3], x[0], x[1], x[2]).normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(x[4], x[5], x[6]);
    return T;
  }
  static void fromIsometry(const Eigen::Isometry3d& T, double* x) {
    const Eigen::Quaterniond q(T.linear());
    x[0] = q.x(), x[1] = q.y(), x[2] = q.z(), x[3] = q.w();
    x[4] = T.translation().x(), x[5] = T.translation().y(), x[6] = T.translation().z();
  }
};

// One cost function for the three observation kinds; R rows (3 stereo, 2 mono, 1 line).
template <int R>
class ObservationCost : public ceres::SizedCostFunction<R, 7, 3> {
 public:
  ObservationCost(const CameraIntrinsics& camera, const testing::SyntheticObservation& obs)
      : camera_(camera), obs_(obs) {
    const Eigen::Matrix<double, R, R> information = obs.information.topLeftCorner<R, R>();
    sqrt_information_ = Eigen::LLT<Eigen::Matrix<double, R, R>>(information).matrixU();  // Omega = U^T U
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Isometry3d T = LeftSe3Manifold::toIsometry(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> P(parameters[1]);
    Eigen::Matrix<double, R, 1> e;
    Eigen::Matrix<double, R, 6> J_pose;
    Eigen::Matrix<double, R, 3> J_point;
    if (!evaluate(T, P, &e, &J_pose, &J_point)) return false;
    Eigen::Map<Eigen::Matrix<double, R, 1>> whitened(residuals);
    whitened = sqrt_information_ * e;
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, R, 7, Eigen::RowMajor>> J(jacobians[0]);
        J.template leftCols<6>() = sqrt_information_ * J_pose;
        J.col(6).setZero();
      }
      if (jacobians[1] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, R, 3, Eigen::RowMajor>> J(jacobians[1]);
        J = sqrt_information_ * J_point;
      }
    }
    return true;
  }

 private:
  bool evaluate(const Eigen::Isometry3d& T, const Eigen::Vector3d& P, Eigen::Matrix<double, R, 1>* e,
                Eigen::Matrix<double, R, 6>* J_pose, Eigen::Matrix<double, R, 3>* J_point) const {
    if constexpr (R == 3) {
      return evaluateStereoPoint(camera_, T, P, obs_.z, e, J_pose, J_point);
    } else if constexpr (R == 2) {
      return evaluateMonoPoint(camera_, T, P, obs_.z.head<2>(), e, J_pose, J_point);
    } else {
      return evaluateLineSample(camera_, T, P, obs_.z, &(*e)(0), J_pose, J_point);
    }
  }
  CameraIntrinsics camera_;
  testing::SyntheticObservation obs_;
  Eigen::Matrix<double, R, R> sqrt_information_;
};

}  // namespace

CeresRunResult solveWithCeres(const testing::SyntheticWindow& window, const LocalBaOptions& options,
                              int iterations) {
  const int num_keyframes = static_cast<int>(window.T_cam_world_initial.size());
  const int num_landmarks = static_cast<int>(window.P_world_initial.size());
  std::vector<double> poses(7 * num_keyframes);
  std::vector<double> points(3 * num_landmarks);
  for (int i = 0; i < num_keyframes; ++i) LeftSe3Manifold::fromIsometry(window.T_cam_world_initial[i], &poses[7 * i]);
  for (int j = 0; j < num_landmarks; ++j) {
    Eigen::Map<Eigen::Vector3d> P(&points[3 * j]);
    P = window.P_world_initial[j];
  }

  ceres::Problem problem;
  // Losses are shared between residual blocks; the problem deletes each distinct one once.
  ceres::LossFunction* loss_stereo = new ceres::SoftLOneLoss(options.kernel_delta_stereo);
  ceres::LossFunction* loss_mono = new ceres::SoftLOneLoss(options.kernel_delta_mono);
  ceres::LossFunction* loss_line = new ceres::SoftLOneLoss(options.kernel_delta_line);
  for (int i = 0; i < num_keyframes; ++i) {
    problem.AddParameterBlock(&poses[7 * i], 7, new LeftSe3Manifold);
    if (window.fixed[i]) problem.SetParameterBlockConstant(&poses[7 * i]);
  }
  for (int j = 0; j < num_landmarks; ++j) problem.AddParameterBlock(&points[3 * j], 3);
  for (const testing::SyntheticObservation& obs : window.observations) {
    double* pose = &poses[7 * obs.keyframe];
    double* point = &points[3 * obs.landmark];
    switch (obs.kind) {
      case ObservationKind::kStereoPoint:
        problem.AddResidualBlock(new ObservationCost<3>(window.camera, obs), loss_stereo, pose, point);
        break;
      case ObservationKind::kMonoPoint:
        problem.AddResidualBlock(new ObservationCost<2>(window.camera, obs), loss_mono, pose, point);
        break;
      case ObservationKind::kLineSample:
        problem.AddResidualBlock(new ObservationCost<1>(window.camera, obs), loss_line, pose, point);
        break;
    }
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.num_threads = 1;
  solver_options.max_num_iterations = iterations;
  solver_options.function_tolerance = 0.0;
  solver_options.gradient_tolerance = 0.0;
  solver_options.parameter_tolerance = 0.0;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.logging_type = ceres::SILENT;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (int j = 0; j < num_landmarks; ++j) ordering->AddElementToGroup(&points[3 * j], 0);
  for (int i = 0; i < num_keyframes; ++i) ordering->AddElementToGroup(&poses[7 * i], 1);
  solver_options.linear_solver_ordering = ordering;

  ceres::Solver::Summary summary;
  timespec cpu_start{}, cpu_stop{};
  const auto start = std::chrono::steady_clock::now();
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu_start);
  ceres::Solve(solver_options, &problem, &summary);
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu_stop);
  const auto stop = std::chrono::steady_clock::now();

  CeresRunResult result;
  result.seconds = std::chrono::duration<double>(stop - start).count();
  result.cpu_seconds = static_cast<double>(cpu_stop.tv_sec - cpu_start.tv_sec) +
                       1e-9 * static_cast<double>(cpu_stop.tv_nsec - cpu_start.tv_nsec);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;  // entry 0 is the start
  result.successful_steps = summary.num_successful_steps;
  return result;
}

}  // namespace plumb::bench
