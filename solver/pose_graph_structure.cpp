// PoseGraph::analyze(): node ordering, the block CSC pattern of H and the symbolic factorisation.
// Everything here depends only on which nodes are free and which pairs share an edge, so it runs
// once per structure; this is the part of optimize() that allocates (see MEMORY in the header).
#include <algorithm>

#include <Eigen/OrderingMethods>

#include "solver/pose_graph.h"

namespace plumb {
namespace {

// An off-diagonal block (row position < col position) as one sortable key: column-major order.
int64_t blockKey(int col, int row) { return (static_cast<int64_t>(col) << 32) | static_cast<int64_t>(row); }
int keyColumn(int64_t key) { return static_cast<int>(key >> 32); }
int keyRow(int64_t key) { return static_cast<int>(key & 0xffffffff); }

}  // namespace

bool PoseGraph::analyze() {
  structure_valid_ = false;
  int num_free = 0;
  for (int n = 0; n < num_nodes_; ++n) nodes_[n].position = nodes_[n].fixed ? -1 : num_free++;
  num_variables_ = num_free;
  if (num_free == 0) return false;

  // Fill-reducing order of the nodes: AMD on the node adjacency. Ordering 6x6 blocks rather than
  // scalars keeps each block's rows contiguous in the pattern, so values are written by offset.
  // reserveChainWithExtraEdges(): the natural order (positions as numbered above).
  if (natural_order_) {
    for (int n = 0; n < num_nodes_; ++n) {
      if (nodes_[n].position >= 0) variable_node_[nodes_[n].position] = n;
    }
  } else {
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(static_cast<size_t>(num_free) + 2 * static_cast<size_t>(num_edges_));
    for (int v = 0; v < num_free; ++v) entries.emplace_back(v, v, 1.0);
    for (int k = 0; k < num_edges_; ++k) {
      const int a = nodes_[edges_[k].i].position;
      const int b = nodes_[edges_[k].j].position;
      if (a < 0 || b < 0) continue;
      entries.emplace_back(a, b, 1.0);
      entries.emplace_back(b, a, 1.0);
    }
    Eigen::SparseMatrix<double> adjacency(num_free, num_free);
    adjacency.setFromTriplets(entries.begin(), entries.end());
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> elimination_order;
    Eigen::AMDOrdering<int>()(adjacency, elimination_order);
    // elimination_order.indices()[p] is the (node-order) variable eliminated p-th.
    std::vector<int> position_of(num_free);
    for (int p = 0; p < num_free; ++p) position_of[elimination_order.indices()[p]] = p;
    for (int n = 0; n < num_nodes_; ++n) {
      Node& node = nodes_[n];
      if (node.position < 0) continue;
      node.position = position_of[node.position];
      variable_node_[node.position] = n;
    }
  }

  // Off-diagonal blocks of the upper triangle, deduplicated (parallel edges share a block).
  int num_keys = 0;
  for (int k = 0; k < num_edges_; ++k) {
    const int a = nodes_[edges_[k].i].position;
    const int b = nodes_[edges_[k].j].position;
    if (a < 0 || b < 0) continue;
    block_keys_[num_keys++] = blockKey(std::max(a, b), std::min(a, b));
  }
  std::sort(block_keys_.begin(), block_keys_.begin() + num_keys);
  num_keys = static_cast<int>(std::unique(block_keys_.begin(), block_keys_.begin() + num_keys) -
                              block_keys_.begin());

  // Scalar CSC pattern of the upper triangle. Column 6P + k holds, rows ascending, the six rows of
  // every off-diagonal block (Q, P), Q < P, then rows 6P .. 6P + k of the diagonal block.
  const int dim = 6 * num_free;
  const int nnz = 21 * num_free + 36 * num_keys;
  H_.resize(dim, dim);
  H_.resizeNonZeros(nnz);
  int* outer = H_.outerIndexPtr();
  int* inner = H_.innerIndexPtr();
  int cursor = 0;
  int key = 0;
  for (int P = 0; P < num_free; ++P) {
    const int first_key = key;
    while (key < num_keys && keyColumn(block_keys_[key]) == P) ++key;
    for (int k = 0; k < 6; ++k) {
      outer[6 * P + k] = cursor;
      for (int t = first_key; t < key; ++t) {
        Block& block = blocks_[num_free + t];
        block.row_position = keyRow(block_keys_[t]);
        block.col_position = P;
        block.column_start[k] = cursor;
        for (int r = 0; r < 6; ++r) inner[cursor++] = 6 * block.row_position + r;
      }
      Block& diagonal = blocks_[P];
      diagonal.row_position = P;
      diagonal.col_position = P;
      diagonal.column_start[k] = cursor;
      for (int r = 0; r <= k; ++r) inner[cursor++] = 6 * P + r;
    }
  }
  outer[dim] = cursor;
  std::fill(H_.valuePtr(), H_.valuePtr() + nnz, 0.0);

  for (int k = 0; k < num_edges_; ++k) {
    Edge& edge = edges_[k];
    const int a = nodes_[edge.i].position;
    const int b = nodes_[edge.j].position;
    edge.off_diagonal_block = -1;
    if (a < 0 || b < 0) continue;
    const int64_t wanted = blockKey(std::max(a, b), std::min(a, b));
    edge.off_diagonal_block =
        num_free +
        static_cast<int>(std::lower_bound(block_keys_.begin(), block_keys_.begin() + num_keys, wanted) -
                         block_keys_.begin());
  }

  factorization_.analyzeOrdered(H_);
  factorization_.reserveDiagonal(dim);
  g_.resize(dim);
  diagonal_.resize(dim);
  dx_.resize(dim);
  structure_valid_ = factorization_.info() == Eigen::Success;
  return structure_valid_;
}

}  // namespace plumb
