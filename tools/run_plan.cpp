// `plumb run`, step 2 of 4 (tools/run_command.h): every check that needs no frame, in one place,
// before any work. Ranges were checked by the parser; here: combinations of flags, the options of
// the system and of the runner (validated once, here), outputs against inputs, the MAVLink
// endpoint, the ground truth, the map, and the source; last the viewer (--serve) binds its address.
#include <unistd.h>

#include <algorithm>
#include <chrono>

#include "drivers/mavlink/mavlink_endpoint.h"
#include "drivers/open/open_source.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/trajectory/trajectory_io.h"
#include "drivers/common/skip_frames_source.h"
#include "tools/io_plan.h"
#include "tools/map_files.h"
#include "tools/run_command.h"

namespace plumb::tools {
namespace {

// Flags that exclude or need each other.
Status checkCombinations(const RunCommandOptions& o) {
  if (!o.save_map.empty() && o.no_loops) {
    return Status::Error("--save-map needs loop closing (the map is the loop closer's keyframe graph): drop --no-loops");
  }
  if (o.out.empty() && !o.discard_trajectory) {
    return Status::Error("--out FILE is required (or --discard-trajectory to run without keeping the poses)");
  }
  if (!o.out.empty() && o.discard_trajectory) return Status::Error("--out and --discard-trajectory exclude each other");
  if (o.progress && o.no_progress) return Status::Error("--progress and --no-progress exclude each other");
  if (!o.mavlink.empty()) {
    MavlinkEndpoint endpoint;
    PLUMB_RETURN_IF_ERROR(parseMavlinkEndpoint(o.mavlink, &endpoint).withContext("--mavlink"));
  }
  return checkServeSpec(o.serve);
}

// The system's and the runner's options from the root, validated (the one place tools/ does it).
Status buildOptions(const RunCommandOptions& o, const std::atomic<bool>* stop, RunPlan* plan) {
  SystemOptions& system = plan->system_options;
  setLineSamples(int(o.line_samples), !o.no_lines, &system.odometry);
  system.odometry.mapper.anchor_line_sample_depth = o.line_depth_anchor;
  system.output_delay_frames = int(o.output_delay);
  system.refine_lag_frames = int(o.refine_lag);
  PLUMB_RETURN_IF_ERROR(validate(system));
  OdometryRunOptions& run = plan->run_options;
  runtime::RunOptions& s = run.schedule;
  PLUMB_RETURN_IF_ERROR(runtime::parseRunMode(o.mode, &s.mode));
  s.slot_count = std::size_t(o.slots);
  s.realtime_priority = int(o.rt_priority);
  s.pin_threads = o.pin_threads;
  s.lock_memory = o.mlock;
  run.max_frames = o.max_frames > 0 ? long(o.max_frames) : -1;
  run.loop_closing = !o.no_loops;
  run.keep_trace = !o.profile.empty();
  run.stop = stop;
  if (!o.save_map.empty()) run.save_map = &plan->saved_map;
  return validate(run);
}

// Every output against every input (tools/io_plan.h).
Status checkFiles(const RunCommandOptions& o) {
  IoPlan io;
  io.addInput(o.dataset);
  io.addInput(o.gt);
  io.addInput(o.camera);
  io.addInput(o.load_map);
  io.addOutput("--save-map", o.save_map);
  io.addOutput("--out", o.out);
  io.addOutput("--covariance", o.covariance);
  io.addOutput("--track-covariance", o.track_covariance);
  io.addOutput("--out-optimized", o.out_optimized);
  io.addOutput("--stats", o.stats);
  io.addOutput("--profile", o.profile);
  return io.check();
}

Status openSource(const RunCommandOptions& o, RunPlan* plan, bool* usage_error) {
  std::unique_ptr<FrameSource> source;
  if (o.synth_noise) {
    std::unique_ptr<SyntheticSource> synth;
    PLUMB_RETURN_IF_ERROR(openSynthSpec(o.dataset, true, &synth));
    plan->scene = &synth->scene();
    source = std::move(synth);
  } else {
    // A dataset reads only the list lines the run will use (--max-frames after --skip-frames).
    SourceOpenOptions open_options;
    if (o.max_frames > 0) open_options.max_frames = std::size_t(o.max_frames + o.skip_frames);
    PLUMB_RETURN_IF_ERROR(openFrameSource(o.dataset, o.camera, open_options, &source));
    if (auto* synth = dynamic_cast<SyntheticSource*>(source.get())) plan->scene = &synth->scene();
  }
  const std::size_t known = source->frameCount();
  if (o.skip_frames > 0 && known > 0 && uint64_t(o.skip_frames) >= known) {
    *usage_error = true;
    return Status::Error("--skip-frames " + std::to_string(o.skip_frames) + " skips all " + std::to_string(known) +
                         " frames of " + source->describe());
  }
  if (o.skip_frames > 0) source = std::make_unique<SkipFramesSource>(std::move(source), uint64_t(o.skip_frames));
  plan->source = std::move(source);
  return Status::Ok();
}

}  // namespace

Status planRun(const RunCommandOptions& o, const std::atomic<bool>* stop, RunPlan* plan, bool* usage_error) {
  *usage_error = true;
  PLUMB_RETURN_IF_ERROR(checkCombinations(o));
  PLUMB_RETURN_IF_ERROR(buildOptions(o, stop, plan));
  PLUMB_RETURN_IF_ERROR(checkFiles(o));
  *usage_error = false;

  // Inputs, cheapest first: a bad ground truth or map costs no set-up of the source.
  if (!o.gt.empty()) PLUMB_RETURN_IF_ERROR(readTumTrajectory(o.gt, &plan->ground_truth).withContext("reading ground truth"));
  if (!o.load_map.empty()) {
    const auto read_start = std::chrono::steady_clock::now();
    PLUMB_RETURN_IF_ERROR(loadMapFile(o.load_map, &plan->loaded_map));
    plan->map_read_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - read_start).count();
    plan->run_options.load_map = &plan->loaded_map;
  }
  PLUMB_RETURN_IF_ERROR(openSource(o, plan, usage_error));

  RunOutputOptions& out = plan->output_options;
  out.trajectory_path = o.out;
  out.covariance_path = o.covariance;
  out.track_covariance_path = o.track_covariance;
  out.optimized_path = o.out_optimized;
  out.rss_every = long(o.rss_every);
  out.report_every = long(o.report_every);
  // Progress: on by default when someone watches (stderr is a terminal), never into a log file.
  const bool terminal = ::isatty(STDERR_FILENO) == 1;
  out.progress = o.progress || (!o.no_progress && terminal);
  out.progress_on_terminal = terminal;
  out.trace = o.trace;
  // Only the ATE needs the poses in memory. A memory-profiling run (--rss-every) keeps nothing
  // per frame, so its resident size can stay flat; it reports no ATE for synthetic scenes.
  out.keep_trajectory = !o.gt.empty() || (plan->scene != nullptr && o.rss_every == 0);
  std::size_t expected = plan->source->frameCount();
  if (o.max_frames > 0 && (expected == 0 || std::size_t(o.max_frames) < expected)) expected = std::size_t(o.max_frames);
  out.expected_frames = expected;
  out.mavlink.endpoint = o.mavlink;
  // Last, once everything else is known to be usable: the viewer binds its address (one in use
  // fails here, before any frame) and serves from now on.
  return plan->serve.start(o.serve, o.mode, o.dataset);
}

}  // namespace plumb::tools
