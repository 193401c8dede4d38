// Pose-graph timings: chains of 100 / 500 / 1000 keyframes with noisy odometry and 10% random loop
// edges, from the drifted odometry start. Prints, per size, the structure analysis (ordering,
// pattern, symbolic LDLT: what allocates) and the LM iterations separately, as medians of thread
// CPU time, plus iterations, costs and the drift before / after.
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <vector>

#include "solver/pose_graph.h"
#include "tests/support/pose_graph_problem.h"

namespace {

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double worstCentreError(const std::vector<Eigen::Isometry3d>& T,
                        const std::vector<Eigen::Isometry3d>& T_true) {
  double worst = 0.0;
  for (size_t k = 0; k < T.size(); ++k) {
    worst = std::max(worst, (T[k].inverse().translation() - T_true[k].inverse().translation()).norm());
  }
  return worst;
}

}  // namespace

int main() {
  using namespace plumb;
  using namespace plumb::testing;
  std::printf(
      "pose graph: chain + 10%% loop edges, noise 0.01 rad / 0.02 m, Huber(2) on loops, one fixed node\n");
  for (int nodes : {100, 500, 1000}) {
    PoseGraphProblemConfig config;
    config.seed = 7;
    config.num_nodes = nodes;
    config.num_loops = nodes / 10;
    config.huber_on_loops = true;
    const PoseGraphProblem p = makePoseGraphProblem(config);
    PoseGraph graph(nodes, static_cast<int>(p.edges.size()));
    const int repeats = nodes >= 1000 ? 5 : 11;
    std::vector<double> analyze_s, solve_s;
    PoseGraphSummary summary;
    for (int r = 0; r < repeats; ++r) {
      loadPoseGraph(p, p.T_initial, &graph);
      const double t0 = threadCpuSeconds();
      graph.analyze();
      const double t1 = threadCpuSeconds();
      summary = graph.optimize(PoseGraphOptions{});
      const double t2 = threadCpuSeconds();
      analyze_s.push_back(t1 - t0);
      solve_s.push_back(t2 - t1);
    }
    std::vector<Eigen::Isometry3d> T;
    for (int k = 0; k < nodes; ++k) T.push_back(graph.pose(k));
    const double per_iteration_ms = 1e3 * median(solve_s) / std::max(1, summary.iterations);
    std::printf(
        "nodes %4d edges %4d: analyze %.3f ms, optimize %.3f ms (%d iterations, %d accepted, %.3f "
        "ms/iteration, "
        "%s), cost %.1f -> %.3f, worst centre error %.3f m -> %.3f m\n",
        nodes, graph.numEdges(), 1e3 * median(analyze_s), 1e3 * median(solve_s), summary.iterations,
        summary.successful_steps, per_iteration_ms, toString(summary.status), summary.initial_cost,
        summary.final_cost, worstCentreError(p.T_initial, p.T_true), worstCentreError(T, p.T_true));
  }
  return 0;
}
