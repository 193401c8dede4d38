#pragma once
// The loop audit (pipeline/loop/loop_audit.h) as the "loop_audit" member of `plumb run --stats`
// (docs/LOOP.md "Loop audit"): every keyframe the loop closer received (id, timestamp) and every
// candidate that reached verification, with its counts, implied correction, plausibility
// chi-square, outcome, and for those verification measured, the loop constraint and its
// covariance. `plumb eval --gt GT --loops STATS.json` reads it back (drivers/trajectory/loop_grading.h).
#include <string>

#include "pipeline/run/odometry_run.h"

namespace plumb {

// `"loop_audit": {...}` (no trailing comma or newline), indented by two spaces.
std::string loopAuditJson(const LoopRunResult& loop);

}  // namespace plumb
