#include <algorithm>
#include <cmath>

#include "drivers/trajectory/evaluate.h"

namespace plumb {

ErrorStatistics computeErrorStatistics(const std::vector<double>& errors) {
  ErrorStatistics stats;
  if (errors.empty()) return stats;
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0, sum_squares = 0;
  for (double e : sorted) {
    sum += e;
    sum_squares += e * e;
  }
  const std::size_t n = sorted.size();
  stats.rmse = std::sqrt(sum_squares / n);
  stats.mean = sum / n;
  // numpy.median: mean of the two middle values for an even count.
  stats.median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  stats.min = sorted.front();
  stats.max = sorted.back();
  return stats;
}

}  // namespace plumb
