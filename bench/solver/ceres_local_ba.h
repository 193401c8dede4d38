#pragma once
// The same local-BA window as a Ceres problem: identical residuals (whitened by the Cholesky
// factor of each information matrix), Pseudo-Huber = ceres::SoftLOneLoss(delta), the left-
// perturbation SE(3) manifold, fixed keyframes constant, DENSE_SCHUR with landmarks eliminated.
#include "solver/local_ba.h"
#include "tests/support/synthetic_window.h"

namespace plumb::bench {

struct CeresRunResult {
  double seconds = 0.0;      // wall time of ceres::Solve only
  double cpu_seconds = 0.0;  // CPU time of this thread in ceres::Solve (num_threads = 1)
  double final_cost = 0.0;
  double initial_cost = 0.0;
  int iterations = 0;
  int successful_steps = 0;
};

// Solves the window from its initial estimate with exactly `iterations` LM iterations
// (tolerances off) on one thread.
CeresRunResult solveWithCeres(const testing::SyntheticWindow& window, const LocalBaOptions& options,
                              int iterations);

}  // namespace plumb::bench
