// Counts every malloc / calloc / realloc of the process (not just operator new, which is what
// platform/allocation_counter.h hooks): Eigen allocates dense and sparse storage with malloc, so an
// operator-new hook alone cannot prove an Eigen code path allocation-free. This executable
// interposes the C allocator, so it is built separately (and not under sanitizers, which interpose
// it themselves). It proves PoseGraph::optimize() on an analysed structure calls none of them.
#include <atomic>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "solver/pose_graph.h"
#include "tests/support/pose_graph_problem.h"

extern "C" void* __libc_malloc(size_t size);
extern "C" void* __libc_calloc(size_t count, size_t size);
extern "C" void* __libc_realloc(void* pointer, size_t size);

namespace {
std::atomic<long> g_malloc_calls{0};
}

extern "C" void* malloc(size_t size) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
extern "C" void* calloc(size_t count, size_t size) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(count, size);
}
extern "C" void* realloc(void* pointer, size_t size) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(pointer, size);
}

namespace plumb::testing {
namespace {

long mallocCalls() { return g_malloc_calls.load(std::memory_order_relaxed); }

TEST(PoseGraphMalloc, TheCounterSeesEigenAndStandardAllocations) {
  const long before = mallocCalls();
  {
    Eigen::VectorXd v(1000);
    v.setZero();
    EXPECT_EQ(v.sum(), 0.0);
  }
  const long after_eigen = mallocCalls();
  {
    std::vector<int> w(1000, 1);
    EXPECT_EQ(w[999], 1);
  }
  EXPECT_GE(after_eigen - before, 1);
  EXPECT_GE(mallocCalls() - after_eigen, 1);
}

TEST(PoseGraphMalloc, OptimizeOnAnAnalysedStructureCallsNoAllocator) {
  for (int nodes : {50, 1000}) {
    PoseGraphProblemConfig config;
    config.seed = 71;
    config.num_nodes = nodes;
    config.num_loops = nodes / 10;
    config.huber_on_loops = true;
    const PoseGraphProblem p = makePoseGraphProblem(config);
    PoseGraph graph(nodes, static_cast<int>(p.edges.size()));
    loadPoseGraph(p, p.T_initial, &graph);
    long before = mallocCalls();
    ASSERT_TRUE(graph.analyze());
    EXPECT_GT(mallocCalls() - before, 0);  // the structure allocates (documented)
    before = mallocCalls();
    PoseGraphSummary summary = graph.optimize(PoseGraphOptions{});
    EXPECT_EQ(mallocCalls() - before, 0) << nodes << " nodes";
    EXPECT_EQ(summary.status, PoseGraphStatus::kConverged);
    EXPECT_GT(summary.iterations, 2);
    before = mallocCalls();
    for (int k = 0; k < nodes; ++k) graph.setPose(k, p.T_initial[k]);
    summary = graph.optimize(PoseGraphOptions{});
    EXPECT_EQ(mallocCalls() - before, 0) << nodes << " nodes, second run";
    EXPECT_TRUE(summary.ok());
  }
}

}  // namespace
}  // namespace plumb::testing
