#pragma once
// `plumb eval --gt GT --loops STATS.json [--json]`: grades a run's loop audit against ground truth
// (drivers/trajectory/loop_grading.h) and prints every accepted loop's error, precision and recall.
#include <string>
#include <vector>

#include "drivers/trajectory/trajectory_io.h"

namespace plumb::tools {

// Returns the process exit code (0 ok, 1 unreadable / no audit).
int evalLoops(const std::vector<StampedPose>& ground_truth, const std::string& stats_path, bool json);

}  // namespace plumb::tools
