// plumb run: the odometry over a dataset, recording, sensor or synthetic scene, through the one
// runner (pipeline/run/odometry_run.h), writing the trajectory (TUM format, lost frames as
// `# <timestamp> lost`, frames real-time mode dropped as `# <timestamp> dropped`), optionally
// keyframe covariances and statistics, and the ATE when ground truth is at hand. Default mode:
// deterministic (lock-step, one thread): same input -> same output bytes.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <set>
#include <string>

#include "drivers/open/open_source.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/common/atomic_file.h"
#include "drivers/common/skip_frames_source.h"
#include "platform/monotonic_time.h"
#include "runtime/chrome_trace.h"
#include "tools/args.h"
#include "tools/command.h"
#include "tools/io_plan.h"
#include "tools/map_files.h"
#include "tools/run_flags.h"
#include "tools/run_outputs.h"

namespace plumb::tools {
namespace {

void printRunUsage() {
  std::printf(
      "usage: plumb run --dataset DIR|SPEC [--camera PRESET|FILE] --out traj.txt [options]\n"
      "  --dataset DIR|SPEC   TUM-format folder, recording, sensor, or synth:PRESET[:SEED[:FRAMES]]\n"
      "                       (textured, low_texture, fast_rotation)\n"
      "  --camera PRESET|FILE tum1 tum2 tum3 icl or a camera file (default: the folder's camera.txt or\n"
      "                       the sensor its name tells)\n"
      "  --out FILE           trajectory, one line per frame (T_world_cam, TUM format); required\n"
      "                       unless --discard-trajectory\n"
      "  --discard-trajectory run without writing the trajectory (statistics or ATE only)\n"
      "  --line-samples N     line-guidance points per line: 0 (points only) or 2..10 (default 5)\n"
      "  --no-lines           points only (lines are neither mapped nor used for tracking)\n"
      "  --out-optimized FILE the optimised trajectory (TUM): every frame through its reference\n"
      "                       keyframe's pose in the final loop-closing pose graph (docs/LOOP.md)\n"
      "  --no-loops           no loop closing (--out-optimized then equals --out)\n"
      "  --covariance FILE    per keyframe: timestamp and the 21 upper-triangle entries of its 6x6\n"
      "                       pose covariance from local BA, then its pose relative to the previous\n"
      "                       keyframe with that covariance (docs/DATA_FORMATS.md)\n"
      "  --track-covariance FILE  per tracked frame: pose and its covariances as MAVLink sends them\n"
      "  --stats FILE         statistics as JSON (states, keyframes, map, ms per frame, RSS, options)\n"
      "  --max-frames N       stop after N frames\n"
      "  --skip-frames N      start at the source's frame N (the first N are read and discarded; 0..)\n"
      "  --save-map FILE      at the end of the run (also after SIGINT), the loop closer's keyframe graph\n"
      "                       and features as a versioned, checksummed map file (docs/LOOP.md \"Map\n"
      "                       files\"); needs loop closing\n"
      "  --load-map FILE      start in a saved map: frames are relocalized against its keyframes until\n"
      "                       one succeeds (`# <t> lost` lines before that), then tracking continues in\n"
      "                       the map's world frame; the map's camera must be this run's\n"
      "  --gt FILE            ground truth (TUM format): print the ATE RMSE (synthetic scenes: exact)\n"
      "  --synth-noise        synthetic scenes with Kinect-like depth and pixel noise\n"
      "  --output-delay N     frames held back so local BA refines them (default 60; 0 = as tracked)\n"
      "  --rss-every N        record peak RSS every N frames in the statistics (poses are then not\n"
      "                       kept in memory: no synthetic ATE unless --gt is given)\n"
      "  --progress           a progress line every 100 frames on stderr\n"
      "  --report-every N     every N frames: sensor-to-pose p50/p99/max, drops and RSS of the block\n"
      "  --trace              one line per frame on stderr: matches, inliers, keyframe, pose\n"
      "  --count-allocations  print heap allocations per frame after a 30-frame warm-up\n"
      "  --mavlink ENDPOINT   MAVLink v2 ODOMETRY + HEARTBEAT to an autopilot, as each pose is tracked:\n"
      "                       udp:HOST:PORT or serial:DEVICE:BAUD (frames: docs/MAVLINK.md)\n"
      "Outputs appear only when complete (written aside, renamed into place); an output that is an\n"
      "input is refused before any work. SIGINT/SIGTERM stop the run cleanly: every pose computed so\n"
      "far is written, the statistics say so, and the exit code is 3.\n"
      "schedule (capture -> extract -> track -> map, docs/RUNTIME.md):\n");
  std::printf("%s", scheduleUsage());
}

std::set<std::string> withScheduleFlags(std::set<std::string> own, const std::set<std::string>& schedule) {
  own.insert(schedule.begin(), schedule.end());
  return own;
}

int fail(const std::string& message, int code = kExitFailed) {
  std::fprintf(stderr, "plumb run: %s\n", message.c_str());
  return code;
}

// SIGINT / SIGTERM: the capture stops reading, the frames already read finish, and every pose
// reaches the outputs. A second signal more than a second after the first is the default action
// (the outputs' temporary files are then left, never a partial file under an output's name). One
// within the second is the same request: `timeout -s INT` sends its signal to the process AND to
// its process group, so a stopped run sees two at once (a run under ASan was killed by the second).
std::atomic<bool> g_stop_requested{false};
volatile std::sig_atomic_t g_stop_signal = 0;
std::atomic<int64_t> g_first_stop_ns{0};

void onStopSignal(int signal) {
  const int64_t now = monotonicNowNs();  // clock_gettime: async-signal-safe
  int64_t first = 0;
  if (g_first_stop_ns.compare_exchange_strong(first, now) || now - first < 1'000'000'000) {
    g_stop_signal = signal;
    g_stop_requested.store(true);
    return;
  }
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

int runRun(int argc, char** argv) {
  Args args(argc, argv,
            withScheduleFlags({"dataset", "camera", "out", "line-samples", "covariance", "stats", "max-frames",
                               "gt", "output-delay", "rss-every", "mavlink", "report-every", "out-optimized",
                               "skip-frames", "save-map", "load-map", "track-covariance"},
                              scheduleValueFlags()),
            withScheduleFlags({"no-lines", "synth-noise", "progress", "trace", "count-allocations", "discard-trajectory",
                               "no-loops"},
                              scheduleSwitchFlags()));
  if (args.help()) {
    printRunUsage();
    return 0;
  }
  if (!args.error().empty() || !args.positional().empty() || !args.has("dataset")) {
    std::fprintf(stderr, "plumb run: %s\n",
                 !args.error().empty()          ? args.error().c_str()
                 : !args.positional().empty() ? ("unexpected argument " + args.positional()[0]).c_str()
                                                : "--dataset is required");
    printRunUsage();
    return 2;
  }
  // From here on a stop request is honoured: one that arrives while the source and the system are
  // being built ends the run before its first frame, cleanly (outputs written, exit code 3).
  std::signal(SIGINT, onStopSignal);
  std::signal(SIGTERM, onStopSignal);
  bool ok = true;
  const long line_samples = args.getInt("line-samples", 5, &ok);
  const long max_frames = args.getInt("max-frames", -1, &ok);
  const long output_delay = args.getInt("output-delay", 60, &ok);
  const long rss_every = args.getInt("rss-every", 0, &ok);
  const long report_every = args.getInt("report-every", 0, &ok);
  const long skip_frames = args.getInt("skip-frames", 0, &ok);
  if (!ok) {
    return fail("--line-samples, --max-frames, --output-delay, --rss-every, --report-every and --skip-frames take integers",
                kExitUsage);
  }
  if (skip_frames < 0) return fail("--skip-frames takes a count >= 0", kExitUsage);
  if (args.has("save-map") && args.has("no-loops")) {
    return fail("--save-map needs loop closing (the map is the loop closer's keyframe graph): drop --no-loops", kExitUsage);
  }
  if (rss_every < 0 || report_every < 0) return fail("--rss-every and --report-every take counts >= 0", kExitUsage);
  if (!args.has("out") && !args.has("discard-trajectory")) {
    return fail("--out FILE is required (or --discard-trajectory to run without keeping the poses)", kExitUsage);
  }
  if (args.has("out") && args.has("discard-trajectory")) return fail("--out and --discard-trajectory exclude each other", kExitUsage);

  // Options are checked where they are used (OdometrySystem::create, validate(OdometryRunOptions)):
  // an impossible value is refused there, with its message, before any frame is read.
  SystemOptions system_options;
  setLineSamples(int(line_samples), !args.has("no-lines"), &system_options.odometry);
  system_options.output_delay_frames = int(output_delay);
  Status st = validate(system_options);
  if (!st.ok()) return fail(st.message(), kExitUsage);
  OdometryRunOptions run_options;
  std::string profile_path;
  st = parseScheduleFlags(args, &run_options, &profile_path);
  if (!st.ok()) return fail(st.message(), kExitUsage);
  run_options.max_frames = max_frames;
  run_options.loop_closing = !args.has("no-loops");
  run_options.keep_trace = !profile_path.empty();
  run_options.stop = &g_stop_requested;
  st = validate(run_options);
  if (!st.ok()) return fail(st.message(), kExitUsage);

  // Every output is checked against every input before any work.
  IoPlan io;
  io.addInput(args.get("dataset"));
  io.addInput(args.get("gt"));
  io.addInput(args.get("camera"));
  io.addInput(args.get("load-map"));
  io.addOutput("--save-map", args.get("save-map"));
  io.addOutput("--out", args.get("out"));
  io.addOutput("--covariance", args.get("covariance"));
  io.addOutput("--track-covariance", args.get("track-covariance"));
  io.addOutput("--out-optimized", args.get("out-optimized"));
  io.addOutput("--stats", args.get("stats"));
  io.addOutput("--profile", profile_path);
  st = io.check();
  if (!st.ok()) return fail(st.message(), kExitUsage);

  // The map is read and checked before the source is opened: a bad map costs no set-up.
  loop::SavedMap loaded_map;
  double map_read_ms = 0;
  if (args.has("load-map")) {
    const auto read_start = std::chrono::steady_clock::now();
    st = loadMapFile(args.get("load-map"), &loaded_map);
    map_read_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - read_start).count();
    if (!st.ok()) return fail(st.message());
    run_options.load_map = &loaded_map;
  }
  loop::SavedMap saved_map;
  if (args.has("save-map")) run_options.save_map = &saved_map;

  const std::string spec = args.get("dataset");
  std::unique_ptr<FrameSource> source;
  const SyntheticScene* scene = nullptr;
  if (args.has("synth-noise")) {
    std::unique_ptr<SyntheticSource> synth;
    st = openSynthSpec(spec, true, &synth);
    if (!st.ok()) return fail(st.message());
    scene = &synth->scene();
    source = std::move(synth);
  } else {
    st = openFrameSource(spec, args.get("camera"), &source);
    if (!st.ok()) return fail(st.message());
    if (auto* synth = dynamic_cast<SyntheticSource*>(source.get())) scene = &synth->scene();
  }
  if (skip_frames > 0) source = std::make_unique<SkipFramesSource>(std::move(source), uint64_t(skip_frames));
  if (args.has("load-map")) {
    const std::string mismatch = loop::cameraMismatch(loaded_map.camera, source->camera());
    if (!mismatch.empty()) {
      return fail("map " + args.get("load-map") + " was made with another camera: " + mismatch);
    }
  }

  RunOutputOptions output_options;
  output_options.trajectory_path = args.get("out");
  output_options.covariance_path = args.get("covariance");
  output_options.track_covariance_path = args.get("track-covariance");
  output_options.optimized_path = args.get("out-optimized");
  output_options.rss_every = rss_every;
  output_options.report_every = report_every;
  output_options.progress = args.has("progress");
  output_options.trace = args.has("trace");
  // Only the ATE needs the poses in memory. A memory-profiling run (--rss-every) keeps nothing
  // per frame, so its resident size can stay flat; it reports no ATE for synthetic scenes.
  output_options.keep_trajectory = args.has("gt") || (scene != nullptr && rss_every == 0);
  std::size_t expected = source->frameCount();
  if (max_frames > 0 && (expected == 0 || std::size_t(max_frames) < expected)) expected = std::size_t(max_frames);
  output_options.expected_frames = expected;
  output_options.mavlink.endpoint = args.get("mavlink");

  RunOutputs outputs(output_options);
  RunRecord record;
  st = runToOutputs(*source, system_options, run_options, outputs, &record);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  // The map is written whatever ended the run (a stop, a read error): like the trajectory, it holds
  // what was computed.
  uint64_t map_bytes = 0;
  if (args.has("save-map") && record.run.loop.enabled) {
    const Status saved = saveMapFile(args.get("save-map"), saved_map, &map_bytes);
    if (!saved.ok()) return fail(saved.message());
    std::printf("map saved: %s, %zu keyframes, %zu loop edges, %llu bytes\n", args.get("save-map").c_str(),
                saved_map.keyframes.size(), saved_map.loop_edges.size(), (unsigned long long)map_bytes);
  }
  // A failed run still wrote every pose it computed (the runner finishes the system whatever ended
  // the run): say so, then fail.
  if (!st.ok()) {
    return fail(st.message() + " (" + std::to_string(outputs.statistics().frames()) +
                " frames processed; their poses were written)");
  }
  const RunStatistics& statistics = outputs.statistics();
  const SourceDamage damage = source->damage();
  if (damage.any()) {
    std::fprintf(stderr,
                 "plumb run: WARNING: the input is damaged: %llu damaged region(s) skipped (%llu bytes), %llu bytes "
                 "of incomplete tail, %s; last: %s. Frames in damaged regions have no trajectory line.\n",
                 (unsigned long long)damage.regions_skipped, (unsigned long long)damage.bytes_skipped,
                 (unsigned long long)damage.truncated_tail_bytes,
                 damage.closed_properly ? "closed properly" : "not closed properly",
                 damage.last.empty() ? "-" : damage.last.c_str());
  }

  double ate = -1;
  std::vector<StampedPose> ground_truth;
  if (args.has("gt")) {
    st = readTumTrajectory(args.get("gt"), &ground_truth).withContext("reading ground truth");
    if (!st.ok()) return fail(st.message());
  } else if (scene != nullptr) {
    ground_truth = syntheticGroundTruth(*scene, long(statistics.frames() + statistics.framesDropped()) + skip_frames);
  }
  double ate_optimized = -1;
  if (!ground_truth.empty() && output_options.keep_trajectory) {
    AteResult result;
    st = evaluateAte(ground_truth, outputs.trajectory(), AteOptions{}, &result);
    if (st.ok()) {
      ate = result.translation_m.rmse;
    } else {
      std::fprintf(stderr, "plumb run: no ATE: %s\n", st.message().c_str());
    }
    if (!outputs.optimizedTrajectory().empty() &&
        evaluateAte(ground_truth, outputs.optimizedTrajectory(), AteOptions{}, &result).ok()) {
      ate_optimized = result.translation_m.rmse;
    }
  }

  const OdometryStats& s = record.odometry;
  std::printf("frames %llu: ok %llu, weak %llu, lost %llu, not initialized %llu; keyframes %llu, "
              "relocalizations %llu, map segments %llu\n",
              (unsigned long long)statistics.frames(), (unsigned long long)s.frames_ok,
              (unsigned long long)s.frames_weak, (unsigned long long)s.frames_lost,
              (unsigned long long)s.frames_not_initialized, (unsigned long long)s.keyframes,
              (unsigned long long)s.relocalizations, (unsigned long long)s.segments);
  std::printf("ms per frame: mean %.2f, p99 %.2f (extract %.2f, track %.2f, map %.2f mean)\n",
              statistics.totalNs().meanNs() * 1e-6, double(statistics.totalNs().percentileNs(0.99)) * 1e-6,
              statistics.extractNs().meanNs() * 1e-6, statistics.trackNs().meanNs() * 1e-6,
              statistics.mapNs().meanNs() * 1e-6);
  const runtime::RunReport& report = record.run.report;
  std::printf("%s: %.1f frames/s, dropped %llu, late %llu, extraction failures %llu, waits for the mapper %llu\n",
              runtime::runModeName(run_options.schedule.mode), report.framesPerSecond(),
              (unsigned long long)report.frames_dropped, (unsigned long long)report.frames_late,
              (unsigned long long)record.run.extraction_failures, (unsigned long long)record.mapper_waits);
  if (args.has("count-allocations")) {
    if (record.run.allocation_frames == 0) {
      std::printf("allocations: run not longer than the %llu-frame warm-up\n",
                  (unsigned long long)run_options.warmup_frames);
    } else {
      std::printf("allocations after warm-up: %llu over %llu frames (%.2f per frame)\n",
                  (unsigned long long)record.run.allocations_after_warmup,
                  (unsigned long long)record.run.allocation_frames,
                  double(record.run.allocations_after_warmup) / double(record.run.allocation_frames));
    }
  }
  if (const MavlinkOdometrySink* mavlink = outputs.mavlink()) {
    const MavlinkStats& m = mavlink->stats();
    std::printf("mavlink %s: odometry sent %llu, heartbeats %llu, dropped %llu, no pose %llu, resets %llu\n",
                output_options.mavlink.endpoint.c_str(), (unsigned long long)m.odometry_sent,
                (unsigned long long)m.heartbeats_sent, (unsigned long long)m.dropped,
                (unsigned long long)m.skipped_no_pose, (unsigned long long)m.resets);
  }
  const LoopRunResult& loop = record.run.loop;
  if (loop.enabled) {
    const loop::LoopStats& ls = loop.stats;
    uint64_t rejected = 0;
    for (int i = 1; i < loop::kNumLoopRejections; ++i) rejected += ls.rejected[i];
    std::printf("loop closing: graph %llu keyframes (capacity %zu), loops found %llu, rejected %llu "
                "(implausible %llu), optimisation %.1f ms total, records dropped %llu\n",
                (unsigned long long)ls.graph_nodes, loop.capacity, (unsigned long long)ls.loops_accepted,
                (unsigned long long)rejected, (unsigned long long)ls.rejected[int(loop::LoopRejection::kImplausible)],
                ls.optimisation_ms_total, (unsigned long long)loop.records_dropped);
  }
  if (args.has("load-map")) {
    const int64_t relocalized = record.odometry.loaded_map_relocalized_frame;
    std::printf("map loaded: %s, %zu keyframes, %zu loop edges; read + checked in %.1f ms, restored in %.1f ms; ",
                args.get("load-map").c_str(), loaded_map.keyframes.size(), loaded_map.loop_edges.size(), map_read_ms,
                record.run.map_restore_ms);
    if (relocalized >= 0) {
      std::printf("relocalized at frame %lld\n", (long long)relocalized);
    } else {
      std::printf("never relocalized\n");
    }
  }
  if (ate >= 0) std::printf("ATE RMSE %.4f m\n", ate);
  if (ate_optimized >= 0) std::printf("ATE RMSE optimized %.4f m\n", ate_optimized);
  if (!profile_path.empty()) {
    st = writeFileAtomically(profile_path, runtime::formatChromeTrace(record.run.trace, report));
    if (!st.ok()) return fail(st.message());
    std::printf("%s", runtime::formatRunReport(report).c_str());
    std::printf("trace: %s (open in ui.perfetto.dev; `plumb profile %s --png hist.png`)\n", profile_path.c_str(),
                profile_path.c_str());
  }
  if (args.has("stats")) {
    RunSummary summary;
    summary.source = source->describe();
    summary.statistics = &statistics;
    summary.run = &record.run;
    summary.odometry = record.odometry;
    summary.mapper = record.mapper;
    summary.system_options = system_options;
    summary.run_options = run_options;
    summary.ate_rmse_m = ate;
    summary.stop_signal = record.run.stopped ? int(g_stop_signal) : 0;
    summary.damaged_regions = damage.regions_skipped;
    summary.damage = damage.last;
    summary.map_loaded = args.has("load-map");
    summary.map_read_ms = map_read_ms;
    summary.map_keyframes = loaded_map.keyframes.size();
    summary.map_loop_edges = loaded_map.loop_edges.size();
    if (args.has("save-map")) {
      summary.map_saved_path = args.get("save-map");
      summary.map_saved_keyframes = saved_map.keyframes.size();
      summary.map_saved_bytes = map_bytes;
    }
    st = writeFileAtomically(args.get("stats"), runSummaryJson(summary));
    if (!st.ok()) return fail(st.message());
  }
  if (record.run.stopped) {
    std::fprintf(stderr, "plumb run: stopped by signal %d after %llu frames; every pose computed was written\n",
                 int(g_stop_signal), (unsigned long long)outputs.statistics().frames());
    return kExitStopped;
  }
  return kExitOk;
}

}  // namespace
}  // namespace plumb::tools

PLUMB_COMMAND(run, "odometry over a dataset or synthetic scene: trajectory, covariances, stats, ATE",
              plumb::tools::runRun);
