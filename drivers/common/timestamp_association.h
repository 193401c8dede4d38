#pragma once
// Timestamp association by the TUM benchmark's rule (associate.py / evaluate_ate.py): consider
// every pair (a, b) with |a - (b + offset)| < max_dt, sort the candidates by (difference, a, b),
// accept greedily while both stamps are still unused, and return the pairs sorted by a.
// Inputs must be sorted ascending (the readers guarantee it).
#include <cstddef>
#include <vector>

namespace plumb {

struct AssociationOptions {
  double max_dt_s = 0.02;  // benchmark default
  double offset_s = 0.0;   // added to the second list's stamps
};

struct IndexPair {
  std::size_t first;   // index into the first list
  std::size_t second;  // index into the second list
};

std::vector<IndexPair> associateTimestamps(const std::vector<double>& first_sorted,
                                           const std::vector<double>& second_sorted,
                                           const AssociationOptions& options = {});

}  // namespace plumb
