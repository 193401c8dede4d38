// `plumb run`, step 1 of 4 (tools/run_command.h): the command line into the options root. Every
// flag is declared once below; the parser (tools/flags.h) checks ranges, empty values, repeats.
#include <cstdio>

#include "pipeline/frontend/capacities.h"
#include "tools/run_command.h"

namespace plumb::tools {

namespace {
// Bounds of counts that are only "large": beyond them a value is a typo (or 1e23), refused before
// anything is allocated or looped over.
constexpr long long kMaxFrameCount = 1'000'000'000'000LL;  // 10^12 frames: a thousand years at 30 Hz
}  // namespace

FlagTable runFlagTable(RunCommandOptions* o) {
  FlagTable t;
  t.text("dataset", "DIR|SPEC", &o->dataset,
         "TUM-format folder, recording, sensor, or synth:PRESET[:SEED[:FRAMES]]\n"
         "(textured, low_texture, fast_rotation); required")
      .text("camera", "PRESET|FILE", &o->camera,
            "tum1 tum2 tum3 icl or a camera file (default: the folder's camera.txt or\n"
            "the sensor its name tells)")
      .text("out", "FILE", &o->out,
            "trajectory, one line per frame (T_world_cam, TUM format); required\n"
            "unless --discard-trajectory")
      .toggle("discard-trajectory", &o->discard_trajectory, "run without writing the trajectory (statistics or ATE only)")
      .integer("line-samples", "N", 0, long(kMaxLineSamples), &o->line_samples,
               "line-guidance points per line: 0 (points only) or 2..10 (default 5)")
      .toggle("no-lines", &o->no_lines, "points only (lines are neither mapped nor used for tracking)")
      .toggle("line-depth-anchor", &o->line_depth_anchor,
              "local BA keeps each line sample's measured depth in the keyframe that\n"
              "made it (experimental, off by default: docs/ODOMETRY.md)")
      .text("out-optimized", "FILE", &o->out_optimized,
            "the optimised trajectory (TUM): every frame through its reference\n"
            "keyframe's pose in the final loop-closing pose graph (docs/LOOP.md)")
      .toggle("no-loops", &o->no_loops, "no loop closing (--out-optimized then equals --out)")
      .text("covariance", "FILE", &o->covariance,
            "per keyframe: timestamp and the 21 upper-triangle entries of its 6x6\n"
            "pose covariance from local BA, then its pose relative to the previous\n"
            "keyframe with that covariance (docs/DATA_FORMATS.md)")
      .text("track-covariance", "FILE", &o->track_covariance,
            "per tracked frame: the pose and its covariances as MAVLink sends them\n"
            "(docs/UNCERTAINTY.md)")
      .text("stats", "FILE", &o->stats,
            "statistics as JSON (states, keyframes, map, ms per frame, RSS, every option)")
      .integer("max-frames", "N", 1, kMaxFrameCount, &o->max_frames, "stop after N frames")
      .integer("skip-frames", "N", 0, kMaxFrameCount, &o->skip_frames,
               "start at the source's frame N (the first N are read and discarded)")
      .text("save-map", "FILE", &o->save_map,
            "at the end of the run (also after a stop), the loop closer's keyframe graph\n"
            "and features as a versioned, checksummed map file (docs/LOOP.md \"Map\n"
            "files\"); needs loop closing; not written when the run made no keyframe")
      .text("load-map", "FILE", &o->load_map,
            "start in a saved map: frames are relocalized against its keyframes until\n"
            "one succeeds (`# <t> lost` lines before that), then tracking continues in\n"
            "the map's world frame; the map's camera must be this run's")
      .text("gt", "FILE", &o->gt, "ground truth (TUM format): print the ATE RMSE (synthetic scenes: exact)")
      .toggle("synth-noise", &o->synth_noise, "synthetic scenes with Kinect-like depth and pixel noise")
      .integer("output-delay", "N", 0, 10'000, &o->output_delay,
               "frames held back so local BA refines them (default 60; 0 = as tracked)")
      .integer("refine-lag", "M", 0, SystemOptions::kMaxRefineLagFrames, &o->refine_lag,
               "split map updates: a keyframe's landmarks reach tracking at the next frame,\n"
               "its local BA M frames later (fast mode overlaps tracking with the BA; the\n"
               "same bytes in every mode but realtime); default 0 = one update after the\n"
               "BA (docs/RUNTIME.md \"Map updates at a fixed lag\")")
      .integer("rss-every", "N", 0, kMaxFrameCount, &o->rss_every,
               "record peak RSS every N frames in the statistics (poses are then not\n"
               "kept in memory: no synthetic ATE unless --gt is given)")
      .toggle("progress", &o->progress,
              "a progress line on stderr: frames, frames/s, ETA (default: on when stderr\n"
              "is a terminal)")
      .toggle("no-progress", &o->no_progress, "no progress line, even on a terminal")
      .integer("report-every", "N", 0, kMaxFrameCount, &o->report_every,
               "every N frames: sensor-to-pose p50/p99/max, drops and RSS of the block")
      .toggle("trace", &o->trace, "one line per frame on stderr: matches, inliers, keyframe, pose")
      .toggle("count-allocations", &o->count_allocations, "print heap allocations per frame after a 30-frame warm-up")
      .text("mavlink", "ENDPOINT", &o->mavlink,
            "MAVLink v2 ODOMETRY + HEARTBEAT to an autopilot, as each pose is tracked:\n"
            "udp:HOST:PORT or serial:DEVICE:BAUD (frames: docs/MAVLINK.md)")
      .text("serve", "PORT|HOST:PORT", &o->serve,
            "watch live: Foxglove WebSocket server + page at http://HOST:PORT/ (PORT\n"
            "alone: this machine only; HOST:PORT binds HOST: anyone who reaches it can\n"
            "watch; docs/VIEWER.md). Read-only: the outputs are the same without it")
      .section("schedule (capture -> extract -> track -> map, docs/RUNTIME.md):")
      .text("mode", "M", &o->mode,
            "deterministic (default: the stages in lock-step on one thread, the\n"
            "same bytes every run), fast (a thread per stage, no drops, the\n"
            "tracker waits for the map after each keyframe: the same bytes as\n"
            "deterministic, faster) or realtime (threads, paced to the recorded\n"
            "timestamps, a frame finding no free slot is dropped and counted)")
      .text("profile", "FILE", &o->profile,
            "write a Chrome trace (Perfetto / chrome://tracing) and print\n"
            "p50/p90/p99/max per stage and end to end, drops, frames/s")
      .integer("slots", "N", 1, 64, &o->slots, "frame slots in flight in the threaded modes (default 8)")
      .integer("rt-priority", "P", 0, 99, &o->rt_priority,
               "SCHED_FIFO priority 1..99 for stage threads (falls back if refused)")
      .toggle("pin-threads", &o->pin_threads, "pin stage threads to CPUs")
      .toggle("mlock", &o->mlock, "lock process memory (falls back if refused)");
  return t;
}

void printRunUsage(const FlagTable& table) {
  std::printf("usage: plumb run --dataset DIR|SPEC [--camera PRESET|FILE] --out traj.txt [options]\n%s",
              table.usage().c_str());
  std::printf(
      "Outputs appear only when complete (written aside, renamed into place; a symlink is written\n"
      "through to its target); an output that is an input is refused before any work. A run that\n"
      "fails before its first frame replaces no output. SIGINT, SIGTERM, SIGHUP and SIGPIPE stop\n"
      "the run cleanly: every pose computed so far is written, the statistics say so, and the exit\n"
      "code is 3.\n");
}

Status parseRunCommand(int argc, char** argv, FlagTable* table, RunCommandOptions* options, bool* help) {
  PLUMB_RETURN_IF_ERROR(table->parse(argc, argv));
  *help = table->help();
  if (*help) return Status::Ok();
  if (!table->positional().empty()) return Status::Error("unexpected argument " + table->positional()[0]);
  if (options->dataset.empty()) return Status::Error("--dataset is required");
  return Status::Ok();
}

}  // namespace plumb::tools
