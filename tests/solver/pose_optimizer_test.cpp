#include "solver/pose_optimizer.h"

#include <memory>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "platform/allocation_counter.h"
#include "solver/se3.h"
#include "tests/support/synthetic_pose_problem.h"

namespace plumb::testing {
namespace {

TEST(PoseOptimizer, RecoversAPerturbedPoseAndClassifiesOutliers) {
  for (bool lm : {false, true}) {
    const PoseProblem p = makePoseProblem(41, 300, 30, 0.15);
    Vector6d delta;
    delta << 0.06, -0.04, 0.08, 0.03, -0.02, 0.025;
    const Eigen::Isometry3d T_initial = applyLeftIncrement(delta, p.T_cam_world_true);
    PoseOptimizerOptions options;
    options.levenberg_marquardt = lm;
    std::unique_ptr<bool[]> point_inliers(new bool[p.points.size()]);
    std::unique_ptr<bool[]> line_inliers(new bool[p.lines.size()]);
    const PoseResult result =
        optimizePose(p.camera, T_initial, p.points.data(), static_cast<int>(p.points.size()), p.lines.data(),
                     static_cast<int>(p.lines.size()), options, point_inliers.get(), line_inliers.get());
    EXPECT_LT(rotationError(result.T_cam_world, p.T_cam_world_true), 1e-3) << "LM " << lm;
    EXPECT_LT(centreError(result.T_cam_world, p.T_cam_world_true), 5e-3) << "LM " << lm;
    EXPECT_LT(result.final_cost, result.initial_cost);

    int outliers = 0, caught = 0, inliers = 0, rejected = 0, counted_inliers = 0;
    for (size_t i = 0; i < p.points.size(); ++i) {
      counted_inliers += point_inliers[i] ? 1 : 0;
      if (p.point_is_outlier[i]) {
        ++outliers;
        caught += point_inliers[i] ? 0 : 1;
      } else {
        ++inliers;
        rejected += point_inliers[i] ? 0 : 1;
      }
    }
    EXPECT_EQ(counted_inliers, result.num_point_inliers);
    ASSERT_GT(outliers, 20);
    EXPECT_EQ(caught, outliers) << "LM " << lm;
    EXPECT_LE(rejected, 0.1 * inliers) << "LM " << lm;  // ~5% by the chi-square threshold itself

    int line_outliers = 0, line_caught = 0, line_inliers_count = 0, line_rejected = 0;
    for (size_t i = 0; i < p.lines.size(); ++i) {
      if (p.line_is_outlier[i]) {
        ++line_outliers;
        line_caught += line_inliers[i] ? 0 : 1;
      } else {
        ++line_inliers_count;
        line_rejected += line_inliers[i] ? 0 : 1;
      }
    }
    ASSERT_GT(line_outliers, 5);
    EXPECT_EQ(line_caught, line_outliers);
    EXPECT_LE(line_rejected, 0.1 * line_inliers_count);

    ASSERT_TRUE(result.covariance_valid);
    EXPECT_TRUE(result.covariance.isApprox(result.covariance.transpose(), 1e-12));
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(result.covariance).eigenvalues()(0), 0.0);
  }
}

// The point-space accumulation against the plain path: H = sum J^T (w Omega) J over the final
// inliers, with the factors' own pose Jacobians; the covariance must be its inverse.
TEST(PoseOptimizer, CovarianceIsTheInverseOfTheInlierHessian) {
  const PoseProblem p = makePoseProblem(45, 200, 20, 0.1);
  Vector6d delta;
  delta << 0.02, -0.01, 0.03, -0.01, 0.02, 0.01;
  std::unique_ptr<bool[]> point_inliers(new bool[p.points.size()]);
  std::unique_ptr<bool[]> line_inliers(new bool[p.lines.size()]);
  const PoseOptimizerOptions options;
  const PoseResult result = optimizePose(p.camera, applyLeftIncrement(delta, p.T_cam_world_true), p.points.data(),
                                         static_cast<int>(p.points.size()), p.lines.data(),
                                         static_cast<int>(p.lines.size()), options, point_inliers.get(),
                                         line_inliers.get());
  ASSERT_TRUE(result.covariance_valid);
  Matrix6d H = Matrix6d::Zero();
  for (size_t i = 0; i < p.points.size(); ++i) {
    if (!point_inliers[i]) continue;
    const PosePointObservation& obs = p.points[i];
    if (obs.has_depth) {
      Eigen::Vector3d e;
      Matrix36d J;
      ASSERT_TRUE(evaluateStereoPoint(p.camera, result.T_cam_world, obs.P_world, obs.z, &e, &J, nullptr));
      const double w = evaluateKernel({options.kernel, options.kernel_delta_stereo}, e.dot(obs.information * e)).rho1;
      H += J.transpose() * (w * obs.information) * J;
    } else {
      Eigen::Vector2d e;
      Matrix26d J;
      ASSERT_TRUE(evaluateMonoPoint(p.camera, result.T_cam_world, obs.P_world, obs.z.head<2>(), &e, &J, nullptr));
      const Eigen::Matrix2d omega = obs.information.topLeftCorner<2, 2>();
      const double w = evaluateKernel({options.kernel, options.kernel_delta_mono}, e.dot(omega * e)).rho1;
      H += J.transpose() * (w * omega) * J;
    }
  }
  for (size_t i = 0; i < p.lines.size(); ++i) {
    if (!line_inliers[i]) continue;
    double e = 0.0;
    RowVector6d J;
    ASSERT_TRUE(evaluateLineSample(p.camera, result.T_cam_world, p.lines[i].P_world, p.lines[i].line, &e, &J, nullptr));
    const double w = evaluateKernel({options.kernel, options.kernel_delta_line}, e * e * p.lines[i].information).rho1;
    H += J.transpose() * (w * p.lines[i].information) * J;
  }
  EXPECT_LT((result.covariance * H - Matrix6d::Identity()).norm(), 1e-9);
}

// More observations of the same quality cannot make the pose less certain.
TEST(PoseOptimizer, WithoutCovarianceGivesTheSamePoseAndInliers) {
  const PoseProblem p = makePoseProblem(46, 200, 20, 0.1);
  Vector6d delta;
  delta << -0.01, 0.02, 0.01, 0.02, -0.01, 0.01;
  const int n = static_cast<int>(p.points.size()), m = static_cast<int>(p.lines.size());
  std::unique_ptr<bool[]> points_a(new bool[n]), lines_a(new bool[m]), points_b(new bool[n]), lines_b(new bool[m]);
  PoseOptimizerOptions options;
  const Eigen::Isometry3d start = applyLeftIncrement(delta, p.T_cam_world_true);
  const PoseResult with = optimizePose(p.camera, start, p.points.data(), n, p.lines.data(), m, options,
                                       points_a.get(), lines_a.get());
  options.compute_covariance = false;
  const PoseResult without = optimizePose(p.camera, start, p.points.data(), n, p.lines.data(), m, options,
                                          points_b.get(), lines_b.get());
  ASSERT_TRUE(with.covariance_valid);
  EXPECT_FALSE(without.covariance_valid);
  EXPECT_EQ(without.final_cost, 0.0);
  EXPECT_TRUE(without.T_cam_world.matrix() == with.T_cam_world.matrix());  // bit for bit
  EXPECT_EQ(without.iterations, with.iterations);
  EXPECT_EQ(without.num_point_inliers, with.num_point_inliers);
  for (int i = 0; i < n; ++i) EXPECT_EQ(points_a[i], points_b[i]);
  for (int i = 0; i < m; ++i) EXPECT_EQ(lines_a[i], lines_b[i]);
}

TEST(PoseOptimizer, CovarianceShrinksWithMoreObservations) {
  const PoseProblem p = makePoseProblem(42, 400, 0, 0.0);
  PoseOptimizerOptions options;
  std::unique_ptr<bool[]> inliers(new bool[p.points.size()]);
  const PoseResult few = optimizePose(p.camera, p.T_cam_world_true, p.points.data(), 100, nullptr, 0, options,
                                      inliers.get(), nullptr);
  const PoseResult many = optimizePose(p.camera, p.T_cam_world_true, p.points.data(), 400, nullptr, 0, options,
                                       inliers.get(), nullptr);
  ASSERT_TRUE(few.covariance_valid && many.covariance_valid);
  EXPECT_LT(many.covariance.trace(), few.covariance.trace());
}

// The map-error term C (sum s_i H_i) C: every landmark as uncertain as its measurement (s = 1)
// gives C itself; exact landmarks (s = 0) give nothing; the estimate and C never depend on s.
TEST(PoseOptimizer, MapCovarianceWeighsEachObservationsInformationByItsShare) {
  PoseProblem p = makePoseProblem(46, 200, 20, 0.0);
  const PoseOptimizerOptions options;
  std::unique_ptr<bool[]> point_inliers(new bool[p.points.size()]);
  std::unique_ptr<bool[]> line_inliers(new bool[p.lines.size()]);
  auto solve = [&](double point_share, double line_share) {
    for (PosePointObservation& o : p.points) o.map_share = point_share;
    for (PoseLineObservation& o : p.lines) o.map_share = line_share;
    return optimizePose(p.camera, p.T_cam_world_true, p.points.data(), static_cast<int>(p.points.size()),
                        p.lines.data(), static_cast<int>(p.lines.size()), options, point_inliers.get(),
                        line_inliers.get());
  };
  const PoseResult exact = solve(0.0, 0.0), once = solve(1.0, 1.0), half = solve(0.5, 0.5);
  const PoseResult points_only = solve(1.0, 0.0);
  ASSERT_TRUE(exact.covariance_valid && once.covariance_valid && half.covariance_valid);
  ASSERT_FALSE(p.lines.empty());
  EXPECT_EQ(exact.map_covariance.norm(), 0.0);
  EXPECT_LT((once.map_covariance - once.covariance).norm(), 1e-9 * once.covariance.norm());
  EXPECT_LT((2.0 * half.map_covariance - once.map_covariance).norm(), 1e-9 * once.covariance.norm());
  // Lines carry part of the information: without their share the term is smaller, not zero.
  EXPECT_GT(points_only.map_covariance.trace(), 0.0);
  EXPECT_LT(points_only.map_covariance.trace(), once.map_covariance.trace());
  EXPECT_TRUE(exact.T_cam_world.isApprox(once.T_cam_world, 0.0));
  EXPECT_TRUE(exact.covariance.isApprox(once.covariance, 0.0));
}

TEST(PoseOptimizer, TooFewObservationsGiveNoCovarianceAndNoNaN) {
  const PoseProblem p = makePoseProblem(43, 1, 0, 0.0);
  bool inlier = false;
  const PoseResult result =
      optimizePose(p.camera, p.T_cam_world_true, p.points.data(), 1, nullptr, 0, PoseOptimizerOptions(), &inlier, nullptr);
  EXPECT_FALSE(result.covariance_valid);
  EXPECT_TRUE(result.T_cam_world.matrix().allFinite());
}

TEST(PoseOptimizer, MakesZeroHeapAllocations) {
  const PoseProblem p = makePoseProblem(44, 200, 20, 0.1);
  std::unique_ptr<bool[]> point_inliers(new bool[p.points.size()]);
  std::unique_ptr<bool[]> line_inliers(new bool[p.lines.size()]);
  Vector6d delta;
  delta << 0.02, 0.01, -0.02, 0.01, 0.0, -0.01;
  const AllocationScope scope;
  const PoseResult result = optimizePose(p.camera, applyLeftIncrement(delta, p.T_cam_world_true), p.points.data(),
                                         200, p.lines.data(), static_cast<int>(p.lines.size()), PoseOptimizerOptions(),
                                         point_inliers.get(), line_inliers.get());
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_GT(result.num_point_inliers, 150);
}

}  // namespace
}  // namespace plumb::testing
