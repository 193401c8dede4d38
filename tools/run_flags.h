#pragma once
// The schedule flags of `plumb run` (docs/RUNTIME.md): --mode --profile --slots --rt-priority
// --pin-threads --mlock, parsed into the runner's options (pipeline/run/odometry_run.h).
#include <set>
#include <string>

#include "pipeline/run/odometry_run.h"
#include "platform/status.h"
#include "tools/args.h"

namespace plumb::tools {

const std::set<std::string>& scheduleValueFlags();  // mode profile slots rt-priority
const std::set<std::string>& scheduleSwitchFlags();  // pin-threads mlock
const char* scheduleUsage();                        // one line per flag, two-space indent

// Fills options->schedule; *profile_path gets --profile ('' when absent).
Status parseScheduleFlags(const Args& args, OdometryRunOptions* options, std::string* profile_path);

}  // namespace plumb::tools
