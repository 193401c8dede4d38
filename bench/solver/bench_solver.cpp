// Solver benchmark (a program that prints numbers; see docs/SOLVER.md for the command).
//  (a) local BA: 10 keyframes (2 fixed), 1,000 points + 100 lines x 5 samples, ~8 observations
//      per landmark, Pseudo-Huber, 10 LM iterations: ours vs Ceres 2.1 DENSE_SCHUR, one thread.
//  (b) pose-only: 1,000 points + 150 lines x 5 samples.
// The last two lines are `speedup_vs_ceres X` and `pose_only_us Y`.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
#include <vector>

#include "bench/solver/ceres_local_ba.h"
#include "solver/local_ba.h"
#include "solver/pose_optimizer.h"
#include "solver/se3.h"
#include "tests/support/synthetic_pose_problem.h"
#include "tests/support/synthetic_window.h"

namespace {

using Clock = std::chrono::steady_clock;

// CPU time of this thread [s]. The benchmark machine is shared, so besides wall time we report
// CPU time, which other processes inflate far less; the summary lines use CPU time.
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

int main() {
  using namespace plumb;
  using namespace plumb::testing;

  // ---- (a) local BA window ------------------------------------------------------------------
  SyntheticWindowConfig config;
  config.seed = 2024;
  config.num_keyframes = 10;
  config.num_fixed = 2;
  config.num_points = 1000;
  config.num_lines = 100;
  config.samples_per_line = 5;
  config.views_per_landmark = 8;
  config.outlier_fraction = 0.01;
  const SyntheticWindow window = makeSyntheticWindow(config);
  const size_t num_landmarks = window.P_world_true.size();
  std::printf("window: %zu keyframes (%d fixed), %zu landmarks, %zu observations (%.2f per landmark)\n",
              window.T_cam_world_true.size(), config.num_fixed, num_landmarks, window.observations.size(),
              static_cast<double>(window.observations.size()) / static_cast<double>(num_landmarks));

  LocalBaOptions options;  // Pseudo-Huber, deltas sqrt(chi2 95%)
  options.max_iterations = 10;
  options.function_tolerance = 0.0;  // exactly 10 iterations, like Ceres below

  const int kOurRuns = 15;
  LocalBundleAdjuster ba;
  std::vector<double> our_seconds, our_cpu_seconds;
  LocalBaSummary our_summary;
  for (int run = 0; run < kOurRuns; ++run) {
    loadWindow(window, /*initial=*/true, &ba);  // untimed: reserve + add
    const Clock::time_point start = Clock::now();
    const double cpu_start = threadCpuSeconds();
    our_summary = ba.solve(options);
    our_cpu_seconds.push_back(threadCpuSeconds() - cpu_start);
    our_seconds.push_back(secondsSince(start));
  }
  const Clock::time_point covariance_start = Clock::now();
  const bool covariance_ok = ba.computeCovariance(options);
  const double covariance_ms = 1e3 * secondsSince(covariance_start);

  const int kCeresRuns = 3;
  std::vector<double> ceres_seconds, ceres_cpu_seconds;
  bench::CeresRunResult ceres;
  for (int run = 0; run < kCeresRuns; ++run) {
    ceres = bench::solveWithCeres(window, options, options.max_iterations);
    ceres_seconds.push_back(ceres.seconds);
    ceres_cpu_seconds.push_back(ceres.cpu_seconds);
  }

  const double our_ms = 1e3 * median(our_cpu_seconds);
  const double ceres_ms = 1e3 * median(ceres_cpu_seconds);
  const double relative_cost_difference =
      std::abs(our_summary.final_cost - ceres.final_cost) / std::max(ceres.final_cost, 1e-300);
  std::printf("local_ba ours:  %.3f ms/solve cpu (wall %.3f, medians of %d), %d iterations (%d accepted), "
              "cost %.10g -> %.10g\n",
              our_ms, 1e3 * median(our_seconds), kOurRuns, our_summary.iterations, our_summary.successful_steps, our_summary.initial_cost,
              our_summary.final_cost);
  std::printf("local_ba ceres: %.3f ms/solve cpu (wall %.3f, medians of %d), %d iterations (%d accepted), "
              "cost %.10g -> %.10g\n",
              ceres_ms, 1e3 * median(ceres_seconds), kCeresRuns, ceres.iterations, ceres.successful_steps, ceres.initial_cost,
              ceres.final_cost);
  std::printf("final_cost_relative_difference %.3e (%s 1e-6)\n", relative_cost_difference,
              relative_cost_difference <= 1e-6 ? "within" : "OUTSIDE");
  std::printf("covariance (%d x %d): %.3f ms, %s\n", 6 * ba.numPoseVariables(), 6 * ba.numPoseVariables(),
              covariance_ms, covariance_ok ? "ok" : "FAILED");
  double worst_rotation = 0.0, worst_centre = 0.0;
  for (int i = 0; i < ba.numKeyframes(); ++i) {
    worst_rotation = std::max(worst_rotation, rotationError(ba.pose(i), window.T_cam_world_true[i]));
    worst_centre = std::max(worst_centre, centreError(ba.pose(i), window.T_cam_world_true[i]));
  }
  std::printf("local_ba worst keyframe error vs truth: %.2e rad, %.2e m\n", worst_rotation, worst_centre);

  // ---- (b) pose-only --------------------------------------------------------------------------
  const PoseProblem pose_problem = makePoseProblem(7, 1000, 150, 0.1);
  Vector6d delta;
  delta << 0.03, -0.02, 0.04, 0.02, -0.015, 0.01;
  const Eigen::Isometry3d T_initial = applyLeftIncrement(delta, pose_problem.T_cam_world_true);
  std::unique_ptr<bool[]> point_inliers(new bool[pose_problem.points.size()]);
  std::unique_ptr<bool[]> line_inliers(new bool[pose_problem.lines.size()]);
  const PoseOptimizerOptions pose_options;
  const int kPoseRuns = 200;
  std::vector<double> pose_seconds, pose_cpu_seconds;
  PoseResult pose_result;
  for (int run = 0; run < kPoseRuns; ++run) {
    const Clock::time_point start = Clock::now();
    const double cpu_start = threadCpuSeconds();
    pose_result = optimizePose(pose_problem.camera, T_initial, pose_problem.points.data(),
                               static_cast<int>(pose_problem.points.size()), pose_problem.lines.data(),
                               static_cast<int>(pose_problem.lines.size()), pose_options, point_inliers.get(),
                               line_inliers.get());
    pose_cpu_seconds.push_back(threadCpuSeconds() - cpu_start);
    pose_seconds.push_back(secondsSince(start));
  }
  std::printf("pose_only: %.1f us cpu (wall %.1f, medians of %d); %zu points + %zu line samples, %d iterations, "
              "inliers %d + %d, error %.2e rad %.2e m\n",
              1e6 * median(pose_cpu_seconds), 1e6 * median(pose_seconds), kPoseRuns, pose_problem.points.size(), pose_problem.lines.size(), pose_result.iterations,
              pose_result.num_point_inliers, pose_result.num_line_inliers,
              rotationError(pose_result.T_cam_world, pose_problem.T_cam_world_true),
              centreError(pose_result.T_cam_world, pose_problem.T_cam_world_true));

  std::printf("speedup_vs_ceres %.2f\n", ceres_ms / our_ms);
  std::printf("pose_only_us %.1f\n", 1e6 * median(pose_cpu_seconds));
  return 0;
}
