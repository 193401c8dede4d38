#pragma once
// SE(3) pose-graph optimisation: sparse Levenberg-Marquardt over keyframe poses linked by measured
// relative poses (odometry / covisibility edges and loop edges). Eigen only.
//
// VARIABLES. One pose per node, stored as T_cam_world like everywhere in solver/ and perturbed on
// the left, T <- expSE3(delta) T, delta = [rho; phi] (solver/se3.h). Fixed nodes keep their pose
// and hold the gauge: optimize() refuses a graph without one (kNoFixedNode), because the cost is
// invariant to moving every pose by the same rigid motion. A connected component without a fixed
// node keeps that freedom; LM damping still yields finite steps there, but the graph is ill posed.
//
// EDGE (i, j). Measures Z = T_i_j, the pose of camera j in camera i (maps points of camera j into
// camera i); exact when Z = T_i T_j^-1 with T_k = T_cam_k_world. Its error is
//
//     E = Z^-1 T_i T_j^-1,        e = logSE3(E) in R^6 ([rho; phi], zero when the edge is met),
//
// i.e. predicted = Z expSE3(e): e is a perturbation of camera j expressed in camera j's frame,
// which is how local BA expresses the covariance of keyframe j with keyframe i fixed. So that
// covariance, inverted, is the edge information Omega directly.
//
// JACOBIANS. Perturbing both poses on the left,
//     Z^-1 expSE3(d_i) T_i T_j^-1 expSE3(-d_j) = expSE3(Ad(Z^-1) d_i) expSE3(-Ad(E) d_j) E,
// and logSE3(expSE3(x) E) = e + J_l(e)^-1 x + O(|x|^2) (solver/se3_jacobians.h), hence
//     J_i = de/dd_i =  J_l(e)^-1 Ad(Z^-1),        J_j = de/dd_j = -J_l(e)^-1 Ad(E).
// Exact (not the J_l ~ I shortcut of g2o), checked against central differences in the tests.
//
// COST. 0.5 * sum_edges rho(e^T Omega e), rho from solver/robust_kernel.h per edge (kNone by
// default; a Huber or Pseudo-Huber kernel on loop edges bounds the pull of a false loop). IRLS:
// each linearisation weights Omega by w = rho'(s), giving H dx = -g with
//     H_ii += J_i^T w Omega J_i,  H_jj += J_j^T w Omega J_j,  H_ij += J_i^T w Omega J_j,
//     g_i  += J_i^T w Omega e,    g_j  += J_j^T w Omega e       (fixed nodes contribute no rows).
//
// SOLVER. H is sparse with 6x6 blocks: one diagonal block per free node, one off-diagonal block
// per pair of free nodes sharing an edge. analyze() builds, once per graph structure, a fill-
// reducing ordering of the NODES (Eigen's AMD on the node adjacency; block-level, so each 6x6
// block stays contiguous), the scalar upper-triangle CSC pattern of H in that order, the value
// offset of every block, and the symbolic LDLT (Eigen::SimplicialLDLT, natural ordering, Upper).
// Each LM iteration then writes values into the fixed pattern, adds the damping and runs the
// numeric factorisation and two triangular solves. Damping, step control and convergence follow
// local BA (solver/local_ba.h): lambda = 1 / trust radius added as lambda * clamp(diag(H), 1e-6,
// 1e32) to the diagonal; a rejected step refactorises from the stored linearisation.
//
// MEMORY. The constructor reserves every per-node, per-edge and per-block buffer for the capacity
// it is given (max_nodes, max_edges); addNode()/addEdge() fail (return -1) when full, never grow.
// analyze() (run by optimize() when nodes or edges were added since the last analysis) allocates
// what depends on the structure: the CSC arrays of H, the AMD ordering's work space, the symbolic
// factor and the dense vectors of the current size. The LM iterations themselves (linearise,
// factorise, solve, evaluate) allocate nothing for graphs of up to ~2,700 free nodes (beyond
// that, Eigen puts the factorisation's 6N-double work vector on the heap instead of the stack).
// A second optimize() on an unchanged structure makes zero calls to malloc, which is what Eigen
// allocates with (tests/solver/malloc replaces malloc to prove it; an operator-new hook would not
// see Eigen's allocations).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "solver/robust_kernel.h"
#include "solver/types.h"

namespace plumb {

struct PoseGraphOptions {
  int max_iterations = 50;            // LM iterations (accepted and rejected steps both count)
  double initial_trust_radius = 1e4;  // lambda = 1 / radius
  double max_trust_radius = 1e16;
  double min_relative_decrease = 1e-3;  // accept a step when actual / predicted exceeds this
  // Converged when an accepted step lowers the cost by less than this fraction of it, or when
  // the quadratic model predicts less than that for a computed step (accepted or not) ...
  double function_tolerance = 1e-12;
  // ... or when a computed step's largest component is below this [m or rad] ...
  double step_tolerance = 1e-12;
  // ... or when the largest gradient component at a linearisation is below this.
  double gradient_tolerance = 1e-14;
};

enum class PoseGraphStatus {
  kConverged,           // one of the tolerances reached
  kMaxIterations,       // ran max_iterations
  kNoVariables,         // every node fixed (or no node): nothing to do
  kNoFixedNode,         // no node fixed: the gauge is free, refused (see the header comment)
  kLinearSolverFailed,  // the damped system could not be factorised at the last attempt
};

const char* toString(PoseGraphStatus status);

struct PoseGraphSummary {
  PoseGraphStatus status = PoseGraphStatus::kNoVariables;
  int iterations = 0;
  int successful_steps = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool ok() const {
    return status == PoseGraphStatus::kConverged || status == PoseGraphStatus::kMaxIterations;
  }
};

// The edge error e = logSE3(T_i_j^-1 T_cam_i_world T_cam_j_world^-1) and its Jacobians with
// respect to left perturbations of the two poses (derivation above). J_i / J_j may be null.
Vector6d poseGraphEdgeError(const Eigen::Isometry3d& T_i_j, const Eigen::Isometry3d& T_cam_i_world,
                            const Eigen::Isometry3d& T_cam_j_world, Matrix6d* J_i = nullptr,
                            Matrix6d* J_j = nullptr);
// The same with the measurement given inverted, T_j_i = T_i_j^-1 (what an edge stores).
Vector6d poseGraphEdgeErrorFromInverse(const Eigen::Isometry3d& T_j_i, const Eigen::Isometry3d& T_cam_i_world,
                                       const Eigen::Isometry3d& T_cam_j_world, Matrix6d* J_i = nullptr,
                                       Matrix6d* J_j = nullptr);

class PoseGraph {
 public:
  // Reserves all per-node and per-edge storage; capacities are fixed for the object's lifetime.
  PoseGraph(int max_nodes, int max_edges);
  PoseGraph(const PoseGraph&) = delete;
  PoseGraph& operator=(const PoseGraph&) = delete;

  // Opt-in for graphs that are a chain in node order plus a bounded number of extra ("loop")
  // edges, e.g. keyframes linked by odometry and loop edges (pipeline/loop/loop_closer.h):
  // analyze() then keeps the nodes in their natural order (no AMD: for a chain with E extra
  // edges the factor has at most 1 + E off-diagonal blocks per block column, so the natural order
  // fills little) and H and the factor get storage for that bound here, once, so a later analyze()
  // makes no operator-new allocation (Eigen's sparse arrays are new[]; the outer index arrays
  // and small dense vectors it still sizes use malloc). A graph beyond the bound still works
  // (Eigen reallocates). The reserved arrays are not written here: the owner makes
  // reservedRanges() resident when it chooses (the loop closer: a slice per keyframe after the
  // first, platform/memory_residency.h), so a long run's memory does not grow as loops fill the
  // factor, and the first frame does not pay for it.
  void reserveChainWithExtraEdges(int max_extra_edges);
  // The arrays reserveChainWithExtraEdges() reserved: H's and the factor's values and indices.
  struct ReservedRange {
    void* data = nullptr;
    std::size_t bytes = 0;
  };
  std::array<ReservedRange, 4> reservedRanges();
  // The factor entries reserveChainWithExtraEdges() reserves: the most a chain of max_nodes with
  // max_extra_edges extra edges can fill in the natural order (derivation in the .cpp; tight when
  // every extra edge spans the whole chain). H and the factor cost 12 bytes an entry.
  static Eigen::Index chainFactorEntries(int max_nodes, int max_extra_edges);

  int maxNodes() const { return max_nodes_; }
  int maxEdges() const { return max_edges_; }
  // Forget nodes and edges; keeps the reserved memory.
  void clear();

  // Returns the node index (0, 1, ... in call order), or -1 when the graph is full or the pose is
  // not finite. `id` is the caller's name for the node (e.g. a keyframe id), kept for findNode().
  int addNode(int64_t id, const Eigen::Isometry3d& T_cam_world, bool fixed);
  // Returns the edge index, or -1 when the edge capacity is full, a node index is out of range,
  // i == j, or T_i_j / information is not finite or information is not symmetric positive definite.
  int addEdge(int node_i, int node_j, const Eigen::Isometry3d& T_i_j, const Matrix6d& information,
              const RobustKernel& kernel = RobustKernel{RobustKernelType::kNone, 1.0});

  // Levenberg-Marquardt from the current poses; updates the free poses in place.
  PoseGraphSummary optimize(const PoseGraphOptions& options);
  // Builds the sparsity pattern, ordering and symbolic factorisation (allocates; see MEMORY).
  // optimize() calls it when the structure changed; call it directly to do that work earlier.
  // Returns false when there is nothing to optimise.
  bool analyze();

  int numNodes() const { return num_nodes_; }
  int numEdges() const { return num_edges_; }
  int findNode(int64_t id) const;  // linear scan; -1 when absent
  int64_t nodeId(int node) const { return nodes_[node].id; }
  bool isFixed(int node) const { return nodes_[node].fixed; }
  const Eigen::Isometry3d& pose(int node) const { return nodes_[node].T_cam_world; }
  // Overwrite a pose (e.g. a new initial guess); the structure stays analysed.
  void setPose(int node, const Eigen::Isometry3d& T_cam_world) { nodes_[node].T_cam_world = T_cam_world; }
  double cost() const;              // 0.5 * sum rho(chi2) at the current poses
  double edgeChi2(int edge) const;  // e^T Omega e at the current poses (e.g. to flag a false loop)

 private:
  struct Node {
    Eigen::Isometry3d T_cam_world = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d T_candidate = Eigen::Isometry3d::Identity();
    int64_t id = 0;
    int position = -1;  // block column of H in the analysed ordering; -1 when fixed
    bool fixed = false;
  };
  struct Edge {
    Eigen::Isometry3d T_j_i = Eigen::Isometry3d::Identity();  // Z^-1, the measurement inverted
    Matrix6d information = Matrix6d::Zero();
    RobustKernel kernel;
    int i = 0;
    int j = 0;
    int off_diagonal_block = -1;  // into blocks_; -1 unless both nodes are free
  };
  // Where a 6x6 block of H lives in the CSC value array: column k of the block starts at
  // column_start[k]; a diagonal block stores rows 0..k of its column k (upper triangle only).
  struct Block {
    int column_start[6] = {0, 0, 0, 0, 0, 0};
    int row_position = 0;
    int col_position = 0;
  };
  // Eigen's sparse LDLT on the upper triangle, in the order analyze() chose (natural ordering
  // here), with three allocation leaks of its public API closed from a subclass (found by counting
  // malloc calls; Eigen allocates with malloc, which an operator-new hook does not see):
  // factorize() constructs a temporary sparse matrix on every call even when it then reads the
  // input directly, vectorD() returns D by value, and D is first sized inside the first
  // factorisation. The protected numeric factorisation and D are used directly instead.
  class Factorization
      : public Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper, Eigen::NaturalOrdering<int>> {
   public:
    void reserveDiagonal(Eigen::Index size) { m_diag.resize(size); }
    void reserveFactor(Eigen::Index size, Eigen::Index nnz) {
      m_matrix.resize(size, size);
      m_matrix.resizeNonZeros(nnz);
    }
    ReservedRange reservedValues() {
      return {m_matrix.valuePtr(), std::size_t(m_matrix.data().allocatedSize()) * sizeof(double)};
    }
    ReservedRange reservedIndices() {
      return {m_matrix.innerIndexPtr(), std::size_t(m_matrix.data().allocatedSize()) * sizeof(int)};
    }
    void factorizeOrdered(const Eigen::SparseMatrix<double>& H_upper) { factorize_preordered<true>(H_upper); }
    // analyzePattern() without its copy of the input into a temporary (new[] every call): the
    // same symbolic analysis (natural ordering, upper triangle) straight on H.
    void analyzeOrdered(const Eigen::SparseMatrix<double>& H_upper) {
      m_Pinv.resize(0);
      m_P.resize(0);
      analyzePattern_preordered(H_upper, true);
    }
    const Eigen::VectorXd& diagonalD() const { return m_diag; }
  };

  double edgeCost(const Edge& edge, const Eigen::Isometry3d& T_i, const Eigen::Isometry3d& T_j) const;
  double linearize();  // fills H_ values, g_, diagonal_; returns the cost
  void addToBlock(const Block& block, const Matrix6d& M, bool transpose);
  bool solveDamped(double lambda);  // damped factorisation and step into dx_
  double modelCostReduction(double lambda) const;
  double candidateCost() const;

  int max_nodes_ = 0;
  int max_edges_ = 0;
  int num_nodes_ = 0;
  int num_edges_ = 0;
  int num_variables_ = 0;  // free nodes in the analysed structure
  bool structure_valid_ = false;
  bool natural_order_ = false;  // reserveChainWithExtraEdges()

  std::vector<Node> nodes_;
  std::vector<Edge> edges_;
  std::vector<Block> blocks_;        // num_variables_ diagonal blocks, then off-diagonal ones
  std::vector<int64_t> block_keys_;  // analyze() scratch: (col, row) pairs of off-diagonal blocks
  std::vector<int> variable_node_;   // position -> node

  Eigen::SparseMatrix<double> H_;  // upper triangle, damped in place per attempt
  Factorization factorization_;
  Eigen::VectorXd g_;         // gradient, by position
  Eigen::VectorXd diagonal_;  // undamped diagonal of H
  Eigen::VectorXd dx_;        // step, by position
};

}  // namespace plumb
