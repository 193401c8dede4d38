// PoseGraph numeric path: IRLS linearisation into the analysed pattern, damped sparse LDLT, and
// the Levenberg-Marquardt loop. Nothing here allocates (see MEMORY in the header).
#include <algorithm>
#include <cmath>

#include "solver/pose_graph.h"
#include "solver/se3.h"
#include "solver/trust_region.h"

namespace plumb {
namespace {

double damping(double lambda, double diagonal) { return lambda * std::clamp(diagonal, 1e-6, 1e32); }

}  // namespace

// Adds M (or M^T) to a block; a diagonal block keeps its upper triangle only (M is symmetric there).
void PoseGraph::addToBlock(const Block& block, const Matrix6d& M, bool transpose) {
  double* values = H_.valuePtr();
  const bool diagonal = block.row_position == block.col_position;
  for (int k = 0; k < 6; ++k) {
    double* column = values + block.column_start[k];
    const int rows = diagonal ? k + 1 : 6;
    if (transpose) {
      for (int r = 0; r < rows; ++r) column[r] += M(k, r);
    } else {
      for (int r = 0; r < rows; ++r) column[r] += M(r, k);
    }
  }
}

double PoseGraph::linearize() {
  std::fill(H_.valuePtr(), H_.valuePtr() + H_.nonZeros(), 0.0);
  g_.setZero();
  double cost = 0.0;
  for (int k = 0; k < num_edges_; ++k) {
    const Edge& edge = edges_[k];
    const Node& node_i = nodes_[edge.i];
    const Node& node_j = nodes_[edge.j];
    Matrix6d J_i;
    Matrix6d J_j;
    const Vector6d e =
        poseGraphEdgeErrorFromInverse(edge.T_j_i, node_i.T_cam_world, node_j.T_cam_world, &J_i, &J_j);
    const Vector6d Omega_e = edge.information * e;
    double rho = 0.0;
    double weight = 1.0;
    robustCostAndWeight(edge.kernel, e.dot(Omega_e), &rho, &weight);
    cost += 0.5 * rho;
    const int a = node_i.position;
    const int b = node_j.position;
    if (a < 0 && b < 0) continue;
    const Matrix6d W = weight * edge.information;
    // Rows J^T W, one per free endpoint; every block of this edge is a product of two of them.
    Matrix6d Jt_W_i;
    Matrix6d Jt_W_j;
    if (a >= 0) {
      Jt_W_i.noalias() = J_i.transpose() * W;
      addToBlock(blocks_[a], Jt_W_i * J_i, false);
      g_.segment<6>(6 * a).noalias() += weight * (J_i.transpose() * Omega_e);
    }
    if (b >= 0) {
      Jt_W_j.noalias() = J_j.transpose() * W;
      addToBlock(blocks_[b], Jt_W_j * J_j, false);
      g_.segment<6>(6 * b).noalias() += weight * (J_j.transpose() * Omega_e);
    }
    if (a >= 0 && b >= 0) {
      // The stored block sits at (row = min position, col = max position): H_ij, or H_ji = H_ij^T.
      addToBlock(blocks_[edge.off_diagonal_block], Jt_W_i * J_j, a > b);
    }
  }
  const int* outer = H_.outerIndexPtr();
  const double* values = H_.valuePtr();
  for (Eigen::Index c = 0; c < H_.cols(); ++c)
    diagonal_[c] = values[outer[c + 1] - 1];  // last row = diagonal
  return cost;
}

bool PoseGraph::solveDamped(double lambda) {
  const int* outer = H_.outerIndexPtr();
  double* values = H_.valuePtr();
  for (Eigen::Index c = 0; c < H_.cols(); ++c)
    values[outer[c + 1] - 1] = diagonal_[c] + damping(lambda, diagonal_[c]);
  factorization_.factorizeOrdered(H_);
  if (factorization_.info() != Eigen::Success) return false;
  // The damped H is positive definite in exact arithmetic; a non-positive pivot means rounding won.
  if (!(factorization_.diagonalD().minCoeff() > 0.0)) return false;
  // L D L^T dx = -g, in place (Solve<> expressions evaluate through a temporary).
  dx_ = -g_;
  factorization_.matrixL().solveInPlace(dx_);
  dx_.array() /= factorization_.diagonalD().array();
  factorization_.matrixU().solveInPlace(dx_);
  return dx_.allFinite();
}

// Decrease of the quadratic model for the step of solveDamped(lambda): with (H + lambda D) dx = -g,
// -(g^T dx + dx^T H dx / 2) = (lambda dx^T D dx - g^T dx) / 2.
double PoseGraph::modelCostReduction(double lambda) const {
  double twice = 0.0;
  for (Eigen::Index c = 0; c < dx_.size(); ++c) {
    twice += damping(lambda, diagonal_[c]) * dx_[c] * dx_[c] - g_[c] * dx_[c];
  }
  return 0.5 * twice;
}

PoseGraphSummary PoseGraph::optimize(const PoseGraphOptions& options) {
  PoseGraphSummary summary;
  bool any_fixed = false;
  bool any_free = false;
  for (int n = 0; n < num_nodes_; ++n) (nodes_[n].fixed ? any_fixed : any_free) = true;
  summary.initial_cost = summary.final_cost = cost();
  if (!any_free) return summary;  // kNoVariables
  if (!any_fixed) {
    summary.status = PoseGraphStatus::kNoFixedNode;
    return summary;
  }
  if (!structure_valid_ && !analyze()) {
    summary.status = PoseGraphStatus::kLinearSolverFailed;
    return summary;
  }
  summary.status = PoseGraphStatus::kMaxIterations;
  double cost = linearize();
  TrustRegion region(options.initial_trust_radius, options.max_trust_radius);
  bool relinearize = false;
  bool last_solve_failed = false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    if (relinearize) cost = linearize();
    relinearize = false;
    if (g_.cwiseAbs().maxCoeff() <= options.gradient_tolerance) {
      summary.status = PoseGraphStatus::kConverged;
      break;
    }
    const double lambda = region.lambda();
    ++summary.iterations;
    const bool step_ok = solveDamped(lambda);
    last_solve_failed = !step_ok;
    double new_cost = cost;
    double predicted = 0.0;
    if (step_ok) {
      for (int n = 0; n < num_nodes_; ++n) {
        Node& node = nodes_[n];
        node.T_candidate = node.position >= 0
                               ? applyLeftIncrement(dx_.segment<6>(6 * node.position), node.T_cam_world)
                               : node.T_cam_world;
      }
      new_cost = candidateCost();
      predicted = modelCostReduction(lambda);
    }
    const double actual = cost - new_cost;
    const double step_quality = TrustRegion::stepQuality(actual, predicted);
    // At the minimum the actual change is rounding noise and steps get rejected forever; the
    // model's own prediction (or a negligible step) says so first, accepted or not.
    const bool nothing_left = step_ok && (predicted <= options.function_tolerance * cost ||
                                          dx_.cwiseAbs().maxCoeff() < options.step_tolerance);
    if (step_ok && std::isfinite(new_cost) && step_quality > options.min_relative_decrease) {
      for (int n = 0; n < num_nodes_; ++n) nodes_[n].T_cam_world = nodes_[n].T_candidate;
      region.stepAccepted(step_quality);
      ++summary.successful_steps;
      relinearize = true;
      const double relative_change = actual / std::max(cost, 1e-300);
      cost = new_cost;
      if (nothing_left || relative_change < options.function_tolerance) {
        summary.status = PoseGraphStatus::kConverged;
        break;
      }
    } else {
      if (nothing_left) {
        summary.status = PoseGraphStatus::kConverged;
        break;
      }
      region.stepRejected();
    }
  }
  if (summary.status == PoseGraphStatus::kMaxIterations && last_solve_failed) {
    summary.status = PoseGraphStatus::kLinearSolverFailed;
  }
  summary.final_cost = cost;
  return summary;
}

}  // namespace plumb
