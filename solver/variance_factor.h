#pragma once
// A posteriori variance factor (the "variance of unit weight" of adjustment theory, Foerstner):
// how large the residuals at a solution are compared with what the noise model predicts. With
// chi2_i = e_i^T Omega_i e_i and r the redundancy (error dof minus the parameters they fix),
// E[sum chi2_i] = sigma0^2 r when every Omega_i is off by the same factor 1/sigma0^2, so
// sigma0^2 * (the covariance from the information) is the covariance the residuals support.
// A value below 1 says the sensor is better than the model (a clean rendering), above 1 worse
// (real depth, blur). It only sees errors that show in residuals: errors shared by the
// observations (a depth bias, a rolling-shutter shear, a landmark error common to many frames)
// need a model-error term of their own (pipeline/odometry/uncertainty_options.h).
//
// Only inliers are summed, and inliers are the residuals below the chi-square thresholds, so the
// sum is of a TRUNCATED distribution: for chi2 = s * chi2_k truncated at q,
//   E[chi2 | chi2 <= q] = s k F_{k+2}(q / s) / F_k(q / s)     (F_k: chi-square CDF, k dof)
// and sigma0^2 = s solves sum chi2 = sum_k n_k s k F_{k+2}(q_k/s) / F_k(q_k/s) * r / n_dof by a
// fixed-point iteration (the truncation matters for s >~ 1: at s = 1, 3 dof, it is 0.85 k).
#include "solver/outlier_thresholds.h"

namespace plumb {

// Inlier chi2 sums and counts by error dof (index 0: 1 dof line samples, 1: 2 dof mono points,
// 2: 3 dof stereo points).
struct InlierChi2Sums {
  double chi2[3] = {0, 0, 0};
  int count[3] = {0, 0, 0};
  void add(int dof, double value) {
    chi2[dof - 1] += value;
    ++count[dof - 1];
  }
  int errorDof() const { return count[0] + 2 * count[1] + 3 * count[2]; }
};

constexpr double kMaxVarianceFactor = 25.0;

// Chi-square CDF for 1..5 dof (closed forms).
double chiSquareCdf(int dof, double x);

// sigma0^2 of the inliers `sums`, whose errors fix `parameters` unknowns; thresholds as used to
// classify them. Returns 1 (the model as it is) when the redundancy is below `min_redundancy`.
double varianceFactor(const InlierChi2Sums& sums, double parameters, const OutlierChi2& thresholds,
                      int min_redundancy = 30);

}  // namespace plumb
