#include "solver/variance_factor.h"

#include <algorithm>
#include <cmath>

namespace plumb {

double chiSquareCdf(int dof, double x) {
  if (!(x > 0)) return 0.0;
  const double h = 0.5 * x;
  const double e = std::exp(-h);
  const double erf_part = std::erf(std::sqrt(h));
  const double odd_term = std::sqrt(2.0 * x / M_PI) * e;
  switch (dof) {
    case 1: return erf_part;
    case 2: return 1.0 - e;
    case 3: return erf_part - odd_term;
    case 4: return 1.0 - e * (1.0 + h);
    case 5: return erf_part - odd_term * (1.0 + x / 3.0);
    default: return 0.0;
  }
}

double varianceFactor(const InlierChi2Sums& sums, double parameters, const OutlierChi2& thresholds,
                      int min_redundancy) {
  const double n_dof = sums.errorDof();
  const double redundancy = n_dof - parameters;
  if (!(redundancy >= min_redundancy)) return 1.0;
  const double total = sums.chi2[0] + sums.chi2[1] + sums.chi2[2];
  const double q[3] = {thresholds.line, thresholds.mono, thresholds.stereo};
  double s = total / redundancy;  // no truncation: the start
  for (int iteration = 0; iteration < 30 && s > 0; ++iteration) {
    double expected_per_s = 0;  // E[sum chi2] / s with truncation, before the redundancy share
    for (int k = 1; k <= 3; ++k) {
      if (sums.count[k - 1] == 0) continue;
      const double Fk = chiSquareCdf(k, q[k - 1] / s);
      const double fraction = Fk > 1e-12 ? chiSquareCdf(k + 2, q[k - 1] / s) / Fk : 0.0;
      expected_per_s += sums.count[k - 1] * k * std::max(fraction, 1e-3);
    }
    const double next = total / (expected_per_s * redundancy / n_dof);
    if (std::abs(next - s) <= 1e-9 * s) {
      s = next;
      break;
    }
    s = next;
  }
  if (!(std::isfinite(s) && s > 0)) return 1.0;
  // Residuals crowding the thresholds have no finite solution (the fixed point runs away): such a
  // window's inliers are not chi-square at any scale; cap it (5x the model's sigma).
  return std::min(s, kMaxVarianceFactor);
}

}  // namespace plumb
