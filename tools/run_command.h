#pragma once
// `plumb run` in four steps, each a function of its own file:
//   parse  (run_parse.cpp)   the command line -> RunCommandOptions, every flag range-checked once
//   plan   (run_plan.cpp)    RunCommandOptions -> RunPlan: combinations checked, outputs checked
//                            against inputs, the map read, the source opened, the system's and the
//                            runner's options built and validated: all before any frame
//   run    (run_execute.cpp) the plan through the one runner into the outputs, the map saved
//   report (run_report.cpp)  the summary lines, the ATE, --profile, --stats; the exit code
// RunCommandOptions is the options root: every flag of `plumb run` is one field here, declared once
// in runFlagTable() (name, range, help), and the `--stats` JSON records every one of them
// ("command_options"), given or default.
#include <atomic>
#include <csignal>
#include <memory>
#include <string>
#include <vector>

#include "drivers/common/frame_source.h"
#include "drivers/synth/synthetic_scene.h"
#include "pipeline/loop/saved_map.h"
#include "platform/status.h"
#include "tools/flags.h"
#include "tools/run_outputs.h"
#include "tools/serve_flag.h"

namespace plumb::tools {

// Every flag of `plumb run`, with its default. Integers are 64-bit here and range-checked by the
// parser; the plan narrows them.
struct RunCommandOptions {
  // input
  std::string dataset;        // --dataset DIR|SPEC (required)
  std::string camera;         // --camera PRESET|FILE ('' = the folder's camera.txt or its name)
  bool synth_noise = false;   // --synth-noise
  long long max_frames = 0;   // --max-frames N (0 = every frame)
  long long skip_frames = 0;  // --skip-frames N
  std::string gt;             // --gt FILE
  std::string load_map;       // --load-map FILE
  // outputs
  std::string out;                  // --out FILE
  bool discard_trajectory = false;  // --discard-trajectory
  std::string out_optimized;        // --out-optimized FILE
  std::string covariance;           // --covariance FILE
  std::string track_covariance;     // --track-covariance FILE
  std::string stats;                // --stats FILE
  std::string save_map;             // --save-map FILE
  std::string mavlink;              // --mavlink ENDPOINT
  std::string serve;                // --serve PORT|HOST:PORT (docs/VIEWER.md)
  // odometry
  long long line_samples = 5;   // --line-samples N
  bool no_lines = false;        // --no-lines
  bool line_depth_anchor = false;  // --line-depth-anchor
  bool no_loops = false;        // --no-loops
  long long output_delay = 60;  // --output-delay N
  long long refine_lag = SystemOptions::kDefaultRefineLagFrames;  // --refine-lag M
  // reporting
  long long rss_every = 0;     // --rss-every N
  long long report_every = 0;  // --report-every N
  bool progress = false;       // --progress (default: on when stderr is a terminal)
  bool no_progress = false;    // --no-progress
  bool trace = false;          // --trace
  bool count_allocations = false;  // --count-allocations
  // schedule (docs/RUNTIME.md)
  std::string mode = "deterministic";  // --mode
  std::string profile;                 // --profile FILE
  long long slots = 8;                 // --slots N
  long long rt_priority = 0;           // --rt-priority P
  bool pin_threads = false;            // --pin-threads
  bool mlock = false;                  // --mlock
};

// The flag table over `options` (tools/flags.h): names, value names, ranges, help lines.
FlagTable runFlagTable(RunCommandOptions* options);

// parse: fills *options through *table (made by runFlagTable over the same options). A Status error
// is a usage error (exit 2). *help: --help was given.
Status parseRunCommand(int argc, char** argv, FlagTable* table, RunCommandOptions* options, bool* help);
void printRunUsage(const FlagTable& table);

// What the plan made: everything the run needs, checked.
struct RunPlan {
  SystemOptions system_options;
  OdometryRunOptions run_options;
  RunOutputOptions output_options;
  std::unique_ptr<FrameSource> source;
  const SyntheticScene* scene = nullptr;  // the synthetic scene (exact ground truth), if any
  std::vector<StampedPose> ground_truth;  // --gt, read before the run
  loop::SavedMap loaded_map;
  double map_read_ms = 0;
  loop::SavedMap saved_map;  // filled by the run when --save-map
  RunServe serve;            // --serve: the viewer, serving from the end of the plan on
};

// plan: a usage problem (combination of flags, an output that is an input) sets *usage_error; any
// other error is a failure of the input (exit 1). `stop` is the run's stop flag.
Status planRun(const RunCommandOptions& options, const std::atomic<bool>* stop, RunPlan* plan, bool* usage_error);

// What the run left.
struct RunExecution {
  RunRecord record;
  Status status;                 // the run's own status (a read error, a refused map...)
  bool outputs_kept = false;     // the trajectory & co. were written under their names
  Status outputs_status;         // why they were not (a full disk), when they were meant to be
  bool map_saved = false;
  uint64_t map_bytes = 0;
  std::string map_note;          // why no map was saved, when --save-map was given
};

// run: the plan through the runner into `outputs`, then --save-map.
void executeRun(const RunCommandOptions& options, RunPlan& plan, RunOutputs& outputs, RunExecution* execution);

// report: prints and writes what the run produced; returns the exit code.
int reportRun(const RunCommandOptions& options, const FlagTable& table, RunPlan& plan, const RunOutputs& outputs,
              RunExecution& execution, int stop_signal);

}  // namespace plumb::tools
