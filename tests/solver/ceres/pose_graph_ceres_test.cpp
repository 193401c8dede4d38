// A second, independent oracle for the pose graph: Ceres (test-only; Debian's libceres-dev),
// with a different parametrisation (each free pose as a Euclidean 6-vector xi around its start,
// T = expSE3(xi) T_start), numeric central-difference Jacobians, Ceres' own HuberLoss and its
// dense solver. Same cost, so the same minimum. Built only when Ceres is found.
#include <algorithm>
#include <cstdio>
#include <vector>

#include <Eigen/Cholesky>
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include "solver/pose_graph.h"
#include "tests/support/pose_graph_problem.h"

namespace plumb::testing {
namespace {

struct EdgeResidual {
  EdgeResidual(const PoseGraphProblemEdge& edge, const Eigen::Isometry3d& start_i,
               const Eigen::Isometry3d& start_j)
      : Z_inv(edge.T_i_j.inverse()), T_start_i(start_i), T_start_j(start_j) {
    sqrt_information = Eigen::LLT<Matrix6d>(edge.information).matrixU();  // Omega = U^T U
  }
  bool operator()(const double* xi_i, const double* xi_j, double* residual) const {
    const Eigen::Isometry3d T_i = expSE3(Eigen::Map<const Vector6d>(xi_i)) * T_start_i;
    const Eigen::Isometry3d T_j = expSE3(Eigen::Map<const Vector6d>(xi_j)) * T_start_j;
    Eigen::Map<Vector6d> r(residual);
    r = sqrt_information * logSE3(Z_inv * T_i * T_j.inverse());
    return true;
  }
  Eigen::Isometry3d Z_inv;
  Eigen::Isometry3d T_start_i;
  Eigen::Isometry3d T_start_j;
  Matrix6d sqrt_information;
};

std::vector<Eigen::Isometry3d> solveWithCeres(const PoseGraphProblem& p, double* final_cost) {
  const int n = static_cast<int>(p.T_initial.size());
  std::vector<double> xi(6 * static_cast<size_t>(n), 0.0);
  ceres::Problem problem;
  for (const PoseGraphProblemEdge& e : p.edges) {
    auto* cost = new ceres::NumericDiffCostFunction<EdgeResidual, ceres::CENTRAL, 6, 6, 6>(
        new EdgeResidual(e, p.T_initial[e.i], p.T_initial[e.j]));
    ceres::LossFunction* loss =
        e.kernel.type == RobustKernelType::kHuber ? new ceres::HuberLoss(e.kernel.delta) : nullptr;
    problem.AddResidualBlock(cost, loss, &xi[6 * e.i], &xi[6 * e.j]);
  }
  for (int k = 0; k < n; ++k)
    if (p.fixed[k]) problem.SetParameterBlockConstant(&xi[6 * k]);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  *final_cost = summary.final_cost;
  std::vector<Eigen::Isometry3d> T(n);
  for (int k = 0; k < n; ++k) T[k] = expSE3(Eigen::Map<const Vector6d>(&xi[6 * k])) * p.T_initial[k];
  return T;
}

TEST(PoseGraphCeres, RandomGraphsMatchCeres) {
  for (unsigned seed : {81u, 82u, 83u}) {
    PoseGraphProblemConfig config;
    config.seed = seed;
    config.num_nodes = 40;
    config.num_loops = 8;
    config.num_fixed = seed == 83u ? 2 : 1;
    config.huber_on_loops = seed != 81u;
    config.num_parallel = 2;
    const PoseGraphProblem p = makePoseGraphProblem(config);
    PoseGraph graph(config.num_nodes, static_cast<int>(p.edges.size()));
    loadPoseGraph(p, p.T_initial, &graph);
    const PoseGraphSummary summary = graph.optimize(PoseGraphOptions{});
    double ceres_cost = 0.0;
    const std::vector<Eigen::Isometry3d> T_ceres = solveWithCeres(p, &ceres_cost);
    double worst_rotation = 0.0;
    double worst_translation = 0.0;
    for (int k = 0; k < config.num_nodes; ++k) {
      worst_rotation = std::max(worst_rotation, rotationDifference(graph.pose(k), T_ceres[k]));
      worst_translation = std::max(worst_translation, translationDifference(graph.pose(k), T_ceres[k]));
    }
    std::printf("seed %u: cost ours %.9f ceres %.9f; worst difference %.2e rad %.2e m\n", seed,
                summary.final_cost, ceres_cost, worst_rotation, worst_translation);
    EXPECT_EQ(summary.status, PoseGraphStatus::kConverged);
    EXPECT_NEAR(summary.final_cost, ceres_cost, 1e-8 * ceres_cost);
    EXPECT_LT(worst_rotation, 1e-6);
    EXPECT_LT(worst_translation, 1e-6);
  }
}

}  // namespace
}  // namespace plumb::testing
