#pragma once
// Seeded random pose graphs (a trajectory, noisy odometry edges, random loop edges) and a dense
// oracle for them: plain Levenberg-Marquardt on the full 6K x 6K system, numeric Jacobians by
// central differences, Eigen's dense LDLT. It shares only expSE3 / logSE3 with solver/pose_graph.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "solver/pose_graph.h"
#include "solver/se3.h"

namespace plumb::testing {

struct PoseGraphProblemConfig {
  unsigned seed = 1;
  int num_nodes = 30;
  int num_loops = 5;                // random loop edges between nodes at least 3 apart
  int num_fixed = 1;                // the first nodes are fixed (at their true pose)
  double sigma_rotation = 0.01;     // measurement noise [rad]
  double sigma_translation = 0.02;  // [m]
  bool huber_on_loops = false;
  int num_parallel = 0;  // extra odometry edges duplicating (k, k+1) pairs
};

struct PoseGraphProblemEdge {
  int i = 0;
  int j = 0;
  Eigen::Isometry3d T_i_j = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Identity();
  RobustKernel kernel{RobustKernelType::kNone, 1.0};
};

struct PoseGraphProblem {
  std::vector<Eigen::Isometry3d> T_true;     // T_cam_world
  std::vector<Eigen::Isometry3d> T_initial;  // odometry composed from the fixed first node
  std::vector<bool> fixed;
  std::vector<PoseGraphProblemEdge> edges;
};

inline Vector6d randomTangent(std::mt19937& rng, double sigma_translation, double sigma_rotation) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Vector6d v;
  for (int d = 0; d < 3; ++d) v[d] = sigma_translation * gauss(rng);
  for (int d = 3; d < 6; ++d) v[d] = sigma_rotation * gauss(rng);
  return v;
}

// A symmetric positive definite information with correlations, scaled like 1 / sigma^2.
inline Matrix6d randomInformation(std::mt19937& rng, double sigma_translation, double sigma_rotation) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Matrix6d M;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) M(r, c) = gauss(rng);
  Vector6d scale;
  scale << Eigen::Vector3d::Constant(1.0 / sigma_translation),
      Eigen::Vector3d::Constant(1.0 / sigma_rotation);
  const Matrix6d correlated = M * M.transpose() / 6.0 + Matrix6d::Identity();
  return scale.asDiagonal() * correlated * scale.asDiagonal();
}

inline PoseGraphProblem makePoseGraphProblem(const PoseGraphProblemConfig& config) {
  std::mt19937 rng(config.seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  PoseGraphProblem p;
  // A wandering trajectory: forward motion with turns, so relative rotations are not tiny.
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  for (int k = 0; k < config.num_nodes; ++k) {
    p.T_true.push_back(T_world_cam.inverse());
    Vector6d motion;
    motion << 0.3 + 0.1 * uniform(rng), 0.1 * uniform(rng), 0.1 * uniform(rng), 0.2 * uniform(rng),
        0.2 + 0.2 * uniform(rng), 0.2 * uniform(rng);
    T_world_cam = T_world_cam * expSE3(motion);
  }
  auto addEdge = [&](int i, int j, bool loop) {
    PoseGraphProblemEdge edge;
    edge.i = i;
    edge.j = j;
    const Eigen::Isometry3d T_i_j_true = p.T_true[i] * p.T_true[j].inverse();
    edge.T_i_j = T_i_j_true * expSE3(randomTangent(rng, config.sigma_translation, config.sigma_rotation));
    edge.information = randomInformation(rng, config.sigma_translation, config.sigma_rotation);
    if (loop && config.huber_on_loops) edge.kernel = RobustKernel{RobustKernelType::kHuber, 2.0};
    p.edges.push_back(edge);
  };
  for (int k = 0; k + 1 < config.num_nodes; ++k) addEdge(k, k + 1, false);
  std::uniform_int_distribution<int> pick(0, config.num_nodes - 1);
  for (int loops = 0; loops < config.num_loops;) {
    const int a = pick(rng);
    const int b = pick(rng);
    if (std::abs(a - b) < 3) continue;
    addEdge(b, a, true);  // either direction occurs: (later, earlier) here
    ++loops;
  }
  for (int k = 0; k < config.num_parallel; ++k) {
    const int a = std::uniform_int_distribution<int>(0, config.num_nodes - 2)(rng);
    addEdge(a, a + 1, false);
  }
  p.fixed.assign(config.num_nodes, false);
  for (int k = 0; k < config.num_fixed && k < config.num_nodes; ++k) p.fixed[k] = true;
  // Initial guess: fixed nodes at the truth, the others chained through the odometry edges.
  p.T_initial = p.T_true;
  for (int k = 1; k < config.num_nodes; ++k) {
    if (!p.fixed[k]) p.T_initial[k] = p.edges[k - 1].T_i_j.inverse() * p.T_initial[k - 1];
  }
  return p;
}

inline void loadPoseGraph(const PoseGraphProblem& p, const std::vector<Eigen::Isometry3d>& poses,
                          PoseGraph* graph) {
  graph->clear();
  for (size_t k = 0; k < poses.size(); ++k)
    graph->addNode(static_cast<int64_t>(1000 + k), poses[k], p.fixed[k]);
  for (const PoseGraphProblemEdge& e : p.edges) graph->addEdge(e.i, e.j, e.T_i_j, e.information, e.kernel);
}

// ---- dense oracle ----

inline Vector6d oracleEdgeError(const PoseGraphProblemEdge& e, const Eigen::Isometry3d& T_i,
                                const Eigen::Isometry3d& T_j) {
  return logSE3(e.T_i_j.inverse() * T_i * T_j.inverse());
}

// Huber written out here (rho(s) and rho'(s) of the squared norm), independent of robust_kernel.h.
inline void oracleKernel(const RobustKernel& k, double s, double* rho, double* weight) {
  if (k.type == RobustKernelType::kNone || s <= k.delta * k.delta) {
    *rho = s;
    *weight = 1.0;
    return;
  }
  *rho = 2.0 * k.delta * std::sqrt(s) - k.delta * k.delta;
  *weight = k.delta / std::sqrt(s);
}

inline double oracleCost(const PoseGraphProblem& p, const std::vector<Eigen::Isometry3d>& T) {
  double cost = 0.0;
  for (const PoseGraphProblemEdge& e : p.edges) {
    const Vector6d r = oracleEdgeError(e, T[e.i], T[e.j]);
    double rho = 0.0;
    double w = 0.0;
    oracleKernel(e.kernel, r.dot(e.information * r), &rho, &w);
    cost += 0.5 * rho;
  }
  return cost;
}

struct DenseOracleResult {
  std::vector<Eigen::Isometry3d> T;
  double cost = 0.0;
  int iterations = 0;
};

inline DenseOracleResult solveDenseOracle(const PoseGraphProblem& p, std::vector<Eigen::Isometry3d> T) {
  const int n = static_cast<int>(T.size());
  std::vector<int> var(n, -1);
  int K = 0;
  for (int k = 0; k < n; ++k)
    if (!p.fixed[k]) var[k] = K++;
  const double h = 1e-6;
  double lambda = 1e-4;
  double cost = oracleCost(p, T);
  DenseOracleResult out;
  for (int it = 0; it < 300; ++it) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(6 * K, 6 * K);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(6 * K);
    for (const PoseGraphProblemEdge& e : p.edges) {
      const Vector6d r = oracleEdgeError(e, T[e.i], T[e.j]);
      double rho = 0.0;
      double w = 0.0;
      oracleKernel(e.kernel, r.dot(e.information * r), &rho, &w);
      Eigen::Matrix<double, 6, 12> J;  // [d r / d delta_i | d r / d delta_j], central differences
      for (int c = 0; c < 6; ++c) {
        const Vector6d d = h * Vector6d::Unit(c);
        J.col(c) = (oracleEdgeError(e, expSE3(d) * T[e.i], T[e.j]) -
                    oracleEdgeError(e, expSE3(-d) * T[e.i], T[e.j])) /
                   (2 * h);
        J.col(6 + c) = (oracleEdgeError(e, T[e.i], expSE3(d) * T[e.j]) -
                        oracleEdgeError(e, T[e.i], expSE3(-d) * T[e.j])) /
                       (2 * h);
      }
      const int idx[2] = {var[e.i], var[e.j]};
      for (int a = 0; a < 2; ++a) {
        if (idx[a] < 0) continue;
        g.segment<6>(6 * idx[a]) += J.middleCols<6>(6 * a).transpose() * w * e.information * r;
        for (int b = 0; b < 2; ++b) {
          if (idx[b] < 0) continue;
          H.block<6, 6>(6 * idx[a], 6 * idx[b]) +=
              J.middleCols<6>(6 * a).transpose() * w * e.information * J.middleCols<6>(6 * b);
        }
      }
    }
    // Simple LM: try steps with growing lambda until the cost goes down.
    bool accepted = false;
    Eigen::VectorXd dx;
    for (int attempt = 0; attempt < 40 && !accepted; ++attempt) {
      Eigen::MatrixXd A = H;
      A.diagonal() += lambda * H.diagonal().cwiseMax(1e-6);
      dx = A.ldlt().solve(-g);
      std::vector<Eigen::Isometry3d> candidate = T;
      for (int k = 0; k < n; ++k)
        if (var[k] >= 0) candidate[k] = expSE3(dx.segment<6>(6 * var[k])) * T[k];
      const double new_cost = oracleCost(p, candidate);
      if (new_cost <= cost) {
        accepted = true;
        T = candidate;
        cost = new_cost;
        lambda = std::max(lambda / 10.0, 1e-12);
      } else {
        lambda *= 10.0;
      }
    }
    out.iterations = it + 1;
    if (!accepted || dx.cwiseAbs().maxCoeff() < 1e-13) break;
  }
  out.T = T;
  out.cost = cost;
  return out;
}

inline double rotationDifference(const Eigen::Isometry3d& A, const Eigen::Isometry3d& B) {
  return logSO3(A.linear() * B.linear().transpose()).norm();
}
inline double translationDifference(const Eigen::Isometry3d& A, const Eigen::Isometry3d& B) {
  return (A.translation() - B.translation()).norm();
}

}  // namespace plumb::testing
