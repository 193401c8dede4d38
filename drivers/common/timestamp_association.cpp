#include "drivers/common/timestamp_association.h"

#include <algorithm>
#include <cmath>

namespace plumb {
namespace {

struct Candidate {
  double difference;
  std::size_t first;
  std::size_t second;
};

}  // namespace

std::vector<IndexPair> associateTimestamps(const std::vector<double>& first_sorted,
                                           const std::vector<double>& second_sorted,
                                           const AssociationOptions& options) {
  // Both lists are sorted, so the candidates of each `a` lie in a sliding window of `b`:
  // O(n * window) instead of the benchmark's all-pairs loop. The window is padded so rounding
  // can never drop a candidate; the exact test is |a - b| < max_dt as in the benchmark.
  const double window = 2.0 * options.max_dt_s;
  std::vector<Candidate> candidates;
  std::size_t window_begin = 0;
  for (std::size_t i = 0; i < first_sorted.size(); ++i) {
    const double a = first_sorted[i];
    while (window_begin < second_sorted.size() && second_sorted[window_begin] + options.offset_s < a - window)
      ++window_begin;
    for (std::size_t j = window_begin; j < second_sorted.size(); ++j) {
      const double b = second_sorted[j] + options.offset_s;
      if (b > a + window) break;
      const double difference = std::abs(a - b);
      if (difference < options.max_dt_s) candidates.push_back({difference, i, j});
    }
  }
  // The benchmark sorts (difference, a, b) tuples; indices order like stamps in sorted lists.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    if (x.difference != y.difference) return x.difference < y.difference;
    if (x.first != y.first) return x.first < y.first;
    return x.second < y.second;
  });
  std::vector<char> first_used(first_sorted.size(), 0), second_used(second_sorted.size(), 0);
  std::vector<IndexPair> pairs;
  for (const Candidate& c : candidates) {
    if (first_used[c.first] || second_used[c.second]) continue;
    first_used[c.first] = second_used[c.second] = 1;
    pairs.push_back({c.first, c.second});
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const IndexPair& x, const IndexPair& y) { return x.first < y.first; });
  return pairs;
}

}  // namespace plumb
