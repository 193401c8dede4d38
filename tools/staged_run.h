#pragma once
// The odometry system as runtime stages (runtime/stage_runner.h):
//
//   capture (FrameSource) ──► extract (FeatureExtractor) ──► odometry (OdometrySystem::processFeatures:
//                                                              track + keyframe + local mapping)
//
// Each slot holds one RgbdImage and one FrameFeatures, allocated once. Extraction is a pure
// function of the image, and tracking + mapping stay on one stage, so every mode produces the same
// poses as the single-threaded processImage() loop: `deterministic` runs lock-step on the calling
// thread, `fast` overlaps extraction of frame n+1 with tracking/mapping of frame n, `realtime` also
// paces the source to the recorded timestamps and drops frames that find no free slot.
//
// runStaged() is what `plumb run --mode ... --profile ...` calls; the caller keeps the per-frame
// bookkeeping (trajectory drains, statistics) in on_output, which runs on the odometry stage's
// thread, in frame order, right after processFeatures().
#include <functional>
#include <set>
#include <string>

#include "drivers/common/frame_source.h"
#include "pipeline/odometry_system.h"
#include "platform/status.h"
#include "runtime/run_options.h"
#include "runtime/run_report.h"
#include "tools/args.h"

namespace plumb::tools {

struct StagedRunOptions {
  runtime::RunMode mode = runtime::RunMode::kDeterministic;
  std::size_t slot_count = 4;    // frames in flight (realtime: more slots = fewer drops, more latency)
  std::string profile_path;      // Chrome trace written here after the run ('' = none)
  bool print_profile = true;     // print the latency table when profile_path is set
  int realtime_priority = 0;     // SCHED_FIFO for stage threads (0 = normal); falls back with a warning
  bool pin_threads = false;      // pin stage threads to CPUs (falls back with a warning)
  bool lock_memory = false;      // mlockall before the run (falls back with a warning)
  long max_frames = -1;          // < 0: until the source ends (dropped frames count too)
  uint64_t warmup_frames = 30;   // allocations are counted from this frame on
};

struct StagedRunResult {
  runtime::RunReport report;
  uint64_t extraction_failures = 0;  // frames whose image did not match the camera (tracked featureless)
  // Frames the odometry stage finished from warmup_frames on, until the capture stage found the
  // input ended (then the stage threads start to exit, and a thread's exit allocates inside
  // OpenCV's thread-local cleanup: shutdown, not per-frame cost).
  uint64_t frames_after_warmup = 0;
  uint64_t allocations_after_warmup = 0;  // process-wide operator new calls between the first and last of them
};

using FrameOutputFn = std::function<Status(const FrameOutput&)>;

// Runs source -> extract -> odometry until the source ends, max_frames, or an error. The system
// must be fresh or continue a previous run; call system.finish() afterwards as usual. A TUM-layout
// replay (TumDatasetSource) is played by index from its first frame, so dropped frames are never
// decoded; other sources are read through next() one frame ahead.
Status runStaged(FrameSource& source, OdometrySystem& system, const StagedRunOptions& options,
                 const FrameOutputFn& on_output, StagedRunResult* result);

// Command-line options understood by parseStagedRunOptions, for the caller's Args sets.
const std::set<std::string>& stagedRunValueOptions();  // mode profile slots rt-priority
const std::set<std::string>& stagedRunFlagOptions();   // pin-threads mlock
// Help text for those options (one per line, two-space indent).
const char* stagedRunUsage();
Status parseStagedRunOptions(const Args& args, StagedRunOptions* options);

}  // namespace plumb::tools
