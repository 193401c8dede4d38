#pragma once
// The odometry system as runtime stages (runtime/stage_runner.h):
//
//   capture (FrameSource) -> extract (FeatureExtractor) -> track (OdometrySystem::trackFeatures)
//     -> map (OdometrySystem::mapFrame: keyframe insertion, local BA, output trajectory)
//              \__ LocalMap snapshots back to track through runtime::LatestSnapshot __/
//
// Each slot holds one RgbdImage, one FrameFeatures and one TrackedFrame (the keyframe request
// travels in it from track to map), allocated once. `deterministic` runs the stages lock-step on
// the calling thread, so every frame is tracked against exactly the map of the single-threaded
// processImage() loop and the output is the same bytes. `fast` and `realtime` run a thread per
// stage: tracking continues against the newest published snapshot while the map stage inserts a
// keyframe, so their trajectories differ slightly from the single-threaded one (timing dependent).
// Map starts and relocalization wait until the map stage has finished every earlier frame
// (MapperFence in pipeline/odometry_system.h). `realtime` also paces the source to the recorded
// timestamps and drops frames that find no free slot; end-to-end latency is measured from the
// sensor time to the end of tracking (pose known).
//
// runStaged() is what `plumb run --mode ... --profile ...` calls; the caller keeps the per-frame
// bookkeeping (trajectory drains, statistics) in on_output, which runs on the map stage's
// thread, in frame order, right after mapFrame().
#include <functional>
#include <set>
#include <string>

#include "drivers/common/frame_source.h"
#include "pipeline/odometry/odometry_system.h"
#include "platform/status.h"
#include "runtime/run_options.h"
#include "runtime/run_report.h"
#include "tools/args.h"

namespace plumb::tools {

struct StagedRunOptions {
  runtime::RunMode mode = runtime::RunMode::kDeterministic;
  // Frames in flight. 8: the front stages keep working through a long local BA in the map stage
  // (~2 frame periods) instead of stalling on a full pool (fast: idle cores; realtime: drops).
  std::size_t slot_count = 8;
  std::string profile_path;      // Chrome trace written here after the run ('' = none)
  bool print_profile = true;     // print the latency table when profile_path is set
  int realtime_priority = 0;     // SCHED_FIFO for stage threads (0 = normal); falls back with a warning
  bool pin_threads = false;      // pin stage threads to CPUs (falls back with a warning)
  bool lock_memory = false;      // mlockall before the run (falls back with a warning)
  long max_frames = -1;          // < 0: until the source ends (dropped frames count too)
  uint64_t warmup_frames = 30;   // allocations are counted from this frame on
  runtime::Clock* clock = nullptr;  // nullptr: the real clock; a VirtualClock simulates realtime mode
};

struct StagedRunResult {
  runtime::RunReport report;
  uint64_t extraction_failures = 0;
  uint64_t drops_without_trajectory_line = 0;  // dropped beyond the drop log's capacity (34 s stall)  // frames whose image did not match the camera (tracked featureless)
  // Frames the map stage finished from warmup_frames on, until the capture stage found the
  // input ended (then the stage threads start to exit, and a thread's exit allocates inside
  // OpenCV's thread-local cleanup: shutdown, not per-frame cost).
  uint64_t frames_after_warmup = 0;
  uint64_t allocations_after_warmup = 0;  // process-wide operator new calls between the first and last of them
};

// Called on the map stage's thread for every frame in order, right after mapFrame(); in realtime
// mode also for each dropped frame, at its place in the order (FrameOutput::dropped, from
// mapDroppedFrame()), so draining the system's finished frames writes it into the trajectory.
using FrameOutputFn = std::function<Status(const FrameOutput&)>;

// Runs source -> extract -> track -> map until the source ends, max_frames, or an error. The system
// must be fresh or continue a previous run; call system.finish() afterwards as usual. The next frame
// is always read (decoded) ahead of its due time, as a sensor delivers finished frames: a
// TUM-layout replay (TumDatasetSource) by index from its first frame, other sources through next().
Status runStaged(FrameSource& source, OdometrySystem& system, const StagedRunOptions& options,
                 const FrameOutputFn& on_output, StagedRunResult* result);

// Command-line options understood by parseStagedRunOptions, for the caller's Args sets.
const std::set<std::string>& stagedRunValueOptions();  // mode profile slots rt-priority
const std::set<std::string>& stagedRunFlagOptions();   // pin-threads mlock
// Help text for those options (one per line, two-space indent).
const char* stagedRunUsage();
Status parseStagedRunOptions(const Args& args, StagedRunOptions* options);

}  // namespace plumb::tools
