// PoseGraph set-up: capacities, nodes and edges, the edge error and its Jacobians, costs.
#include "solver/pose_graph.h"

#include <algorithm>

#include <Eigen/Cholesky>

#include "solver/se3.h"
#include "solver/se3_jacobians.h"

namespace plumb {
namespace {

bool isFinitePose(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

bool isSymmetricPositiveDefinite(const Matrix6d& A) {
  if (!A.allFinite()) return false;
  const double scale = A.cwiseAbs().maxCoeff();
  if (!(scale > 0.0) || (A - A.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  const Eigen::LLT<Matrix6d> llt(A);  // fixed size: no heap
  return llt.info() == Eigen::Success;
}

}  // namespace

Vector6d poseGraphEdgeErrorFromInverse(const Eigen::Isometry3d& T_j_i, const Eigen::Isometry3d& T_cam_i_world,
                                       const Eigen::Isometry3d& T_cam_j_world, Matrix6d* J_i, Matrix6d* J_j) {
  const Eigen::Isometry3d E = T_j_i * T_cam_i_world * T_cam_j_world.inverse();
  const Vector6d e = logSE3(E);
  if (J_i == nullptr && J_j == nullptr) return e;
  const Matrix6d J_l_inv = leftJacobianInverseSE3(e);
  if (J_i != nullptr) J_i->noalias() = J_l_inv * adjointSE3(T_j_i);
  if (J_j != nullptr) J_j->noalias() = -J_l_inv * adjointSE3(E);
  return e;
}

Vector6d poseGraphEdgeError(const Eigen::Isometry3d& T_i_j, const Eigen::Isometry3d& T_cam_i_world,
                            const Eigen::Isometry3d& T_cam_j_world, Matrix6d* J_i, Matrix6d* J_j) {
  return poseGraphEdgeErrorFromInverse(T_i_j.inverse(), T_cam_i_world, T_cam_j_world, J_i, J_j);
}

const char* toString(PoseGraphStatus status) {
  switch (status) {
    case PoseGraphStatus::kConverged:
      return "converged";
    case PoseGraphStatus::kMaxIterations:
      return "max_iterations";
    case PoseGraphStatus::kNoVariables:
      return "no_variables";
    case PoseGraphStatus::kNoFixedNode:
      return "no_fixed_node";
    case PoseGraphStatus::kLinearSolverFailed:
      return "linear_solver_failed";
  }
  return "unknown";
}

PoseGraph::PoseGraph(int max_nodes, int max_edges)
    : max_nodes_(std::max(0, max_nodes)), max_edges_(std::max(0, max_edges)) {
  nodes_.resize(max_nodes_);
  edges_.resize(max_edges_);
  blocks_.resize(static_cast<size_t>(max_nodes_) + max_edges_);
  block_keys_.resize(max_edges_);
  variable_node_.resize(max_nodes_);
}

Eigen::Index PoseGraph::chainFactorEntries(int max_nodes, int max_extra_edges) {
  // Natural order, chain k -> k+1 plus extra edges. Eliminating block column k links the rows it
  // holds, all after k, so by induction column k holds row k+1 and the far ends j > k of the
  // extra edges (i, j) with i <= k < j: at most 1 + E blocks, and never more than the n - 1 - k
  // block rows below it. 15 strictly-lower entries inside each diagonal block, 36 per block.
  const Eigen::Index n = std::max(0, max_nodes);
  const Eigen::Index per_column = 1 + std::max(0, max_extra_edges);
  Eigen::Index entries = 0;
  for (Eigen::Index k = 0; k < n; ++k) entries += 15 + 36 * std::min(per_column, n - 1 - k);
  return entries;
}

void PoseGraph::reserveChainWithExtraEdges(int max_extra_edges) {
  natural_order_ = true;
  const Eigen::Index dim = 6 * Eigen::Index(max_nodes_);
  // H: 21 entries per diagonal block, 36 per off-diagonal block (one per edge at most).
  H_.resize(dim, dim);
  const Eigen::Index h_entries = 21 * Eigen::Index(max_nodes_) + 36 * Eigen::Index(max_edges_);
  H_.resizeNonZeros(h_entries);
  factorization_.reserveFactor(dim, chainFactorEntries(max_nodes_, max_extra_edges));
}

std::array<PoseGraph::ReservedRange, 4> PoseGraph::reservedRanges() {
  const std::size_t h_entries = std::size_t(H_.data().allocatedSize());
  return {ReservedRange{H_.valuePtr(), h_entries * sizeof(double)},
          ReservedRange{H_.innerIndexPtr(), h_entries * sizeof(int)}, factorization_.reservedValues(),
          factorization_.reservedIndices()};
}

void PoseGraph::clear() {
  num_nodes_ = 0;
  num_edges_ = 0;
  num_variables_ = 0;
  structure_valid_ = false;
}

int PoseGraph::addNode(int64_t id, const Eigen::Isometry3d& T_cam_world, bool fixed) {
  if (num_nodes_ >= max_nodes_ || !isFinitePose(T_cam_world)) return -1;
  Node& node = nodes_[num_nodes_];
  node.T_cam_world = T_cam_world;
  node.T_candidate = T_cam_world;
  node.id = id;
  node.fixed = fixed;
  node.position = -1;
  structure_valid_ = false;
  return num_nodes_++;
}

int PoseGraph::addEdge(int node_i, int node_j, const Eigen::Isometry3d& T_i_j, const Matrix6d& information,
                       const RobustKernel& kernel) {
  if (num_edges_ >= max_edges_ || node_i < 0 || node_j < 0 || node_i >= num_nodes_ || node_j >= num_nodes_ ||
      node_i == node_j || !isFinitePose(T_i_j) || !isSymmetricPositiveDefinite(information) ||
      !(kernel.type == RobustKernelType::kNone || kernel.delta > 0.0)) {
    return -1;
  }
  Edge& edge = edges_[num_edges_];
  edge.T_j_i = T_i_j.inverse();
  edge.information = 0.5 * (information + information.transpose());
  edge.kernel = kernel;
  edge.i = node_i;
  edge.j = node_j;
  edge.off_diagonal_block = -1;
  structure_valid_ = false;
  return num_edges_++;
}

int PoseGraph::findNode(int64_t id) const {
  for (int n = 0; n < num_nodes_; ++n) {
    if (nodes_[n].id == id) return n;
  }
  return -1;
}

double PoseGraph::edgeCost(const Edge& edge, const Eigen::Isometry3d& T_i,
                           const Eigen::Isometry3d& T_j) const {
  const Vector6d e = poseGraphEdgeErrorFromInverse(edge.T_j_i, T_i, T_j, nullptr, nullptr);
  double rho = 0.0;
  double weight = 0.0;
  robustCostAndWeight(edge.kernel, e.dot(edge.information * e), &rho, &weight);
  return 0.5 * rho;
}

double PoseGraph::cost() const {
  double total = 0.0;
  for (int k = 0; k < num_edges_; ++k) {
    const Edge& edge = edges_[k];
    total += edgeCost(edge, nodes_[edge.i].T_cam_world, nodes_[edge.j].T_cam_world);
  }
  return total;
}

double PoseGraph::candidateCost() const {
  double total = 0.0;
  for (int k = 0; k < num_edges_; ++k) {
    const Edge& edge = edges_[k];
    total += edgeCost(edge, nodes_[edge.i].T_candidate, nodes_[edge.j].T_candidate);
  }
  return total;
}

double PoseGraph::edgeChi2(int edge_index) const {
  const Edge& edge = edges_[edge_index];
  const Vector6d e = poseGraphEdgeErrorFromInverse(edge.T_j_i, nodes_[edge.i].T_cam_world,
                                                   nodes_[edge.j].T_cam_world, nullptr, nullptr);
  return e.dot(edge.information * e);
}

}  // namespace plumb
