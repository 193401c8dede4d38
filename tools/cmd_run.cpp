// plumb run: the odometry system over a dataset folder or a synthetic scene, writing the
// trajectory (TUM format, lost frames as `# <timestamp> lost`, frames real-time mode dropped as
// `# <timestamp> dropped`), optionally keyframe covariances and statistics, and the ATE when ground
// truth is at hand. Same input -> same output bytes. Single-threaded by default; --mode runs the
// same system as runtime stages (tools/staged_run.h), where deterministic gives the single-threaded
// bytes, fast tracks against a map one keyframe behind at times, and realtime may drop frames.
#include <cstdio>
#include <memory>
#include <set>
#include <string>

#include "drivers/common/open_source.h"
#include "tools/args.h"
#include "tools/command.h"
#include "tools/odometry_session.h"
#include "tools/staged_run.h"

namespace plumb::tools {
namespace {

void printRunUsage() {
  std::printf(
      "usage: plumb run --dataset DIR|SPEC [--camera PRESET|FILE] --out traj.txt [options]\n"
      "  --dataset DIR|SPEC   TUM-format folder, or synth:PRESET[:SEED[:FRAMES]] (textured, low_texture,\n"
      "                       fast_rotation)\n"
      "  --camera PRESET|FILE tum1 tum2 tum3 icl or a camera file (default: the folder's camera.txt or\n"
      "                       the sensor its name tells)\n"
      "  --out FILE           trajectory, one line per frame (T_world_cam, TUM format)\n"
      "  --line-samples N     line-guidance points per line, 0..10 (default 5; 0 = points only)\n"
      "  --no-lines           points only (lines are neither mapped nor used for tracking)\n"
      "  --covariance FILE    per keyframe: timestamp and the 21 upper-triangle entries of its 6x6\n"
      "                       pose covariance from local BA (docs/ODOMETRY.md)\n"
      "  --stats FILE         statistics as JSON (states, keyframes, map, ms per frame, RSS)\n"
      "  --max-frames N       stop after N frames\n"
      "  --gt FILE            ground truth (TUM format): print the ATE RMSE (synthetic scenes: exact)\n"
      "  --synth-noise        synthetic scenes with Kinect-like depth and pixel noise\n"
      "  --output-delay N     frames held back so local BA refines them (default 60; 0 = as tracked)\n"
      "  --rss-every N        record peak RSS every N frames in the statistics (poses are then not\n"
      "                       kept in memory: no synthetic ATE unless --gt is given)\n"
      "  --progress           a progress line every 100 frames on stderr\n"
      "  --trace              one line per frame on stderr: matches, inliers, keyframe, pose\n"
      "  --count-allocations  print heap allocations per frame after a 30-frame warm-up\n"
      "staged pipeline (capture -> extract -> odometry, docs/RUNTIME.md); without --mode the run is\n"
      "single-threaded and the options below are refused:\n");
  std::printf("%s", stagedRunUsage());
}

// The option sets of `plumb run`: its own plus the staged-pipeline ones.
std::set<std::string> withStagedOptions(std::set<std::string> own, const std::set<std::string>& staged) {
  own.insert(staged.begin(), staged.end());
  return own;
}

int fail(const std::string& message) {
  std::fprintf(stderr, "plumb run: %s\n", message.c_str());
  return 1;
}

int runRun(int argc, char** argv) {
  Args args(argc, argv,
            withStagedOptions({"dataset", "camera", "out", "line-samples", "covariance", "stats", "max-frames",
                               "gt", "output-delay", "rss-every"},
                              stagedRunValueOptions()),
            withStagedOptions({"no-lines", "synth-noise", "progress", "trace", "count-allocations"},
                              stagedRunFlagOptions()));
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
  bool ok = true;
  const long line_samples = args.getInt("line-samples", 5, &ok);
  const long max_frames = args.getInt("max-frames", -1, &ok);
  const long output_delay = args.getInt("output-delay", 60, &ok);
  const long rss_every = args.getInt("rss-every", 0, &ok);
  if (!ok) return fail("--line-samples, --max-frames, --output-delay and --rss-every take integers");
  if (line_samples < 0 || line_samples > long(kMaxLineSamples)) {
    return fail("--line-samples must be within 0.." + std::to_string(kMaxLineSamples));
  }
  if (output_delay < 0 || output_delay >= OdometryTrajectory::kMaxDelayFrames) {
    return fail("--output-delay must be within 0.." + std::to_string(OdometryTrajectory::kMaxDelayFrames - 1));
  }

  // Staged options only mean something with --mode; refusing them keeps a typo'd run from silently
  // being single-threaded.
  StagedRunOptions staged;
  if (args.has("mode")) {
    const Status st = parseStagedRunOptions(args, &staged);
    if (!st.ok()) return fail(st.message());
  } else {
    for (const auto* names : {&stagedRunValueOptions(), &stagedRunFlagOptions()}) {
      for (const std::string& name : *names) {
        if (args.has(name)) return fail("--" + name + " needs --mode realtime|fast|deterministic");
      }
    }
  }

  const std::string spec = args.get("dataset");
  std::unique_ptr<FrameSource> source;
  const SyntheticScene* scene = nullptr;
  if (args.has("synth-noise")) {
    std::unique_ptr<SyntheticSource> synth;
    const Status st = openNoisySynthetic(spec, &synth);
    if (!st.ok()) return fail(st.message());
    scene = &synth->scene();
    source = std::move(synth);
  } else {
    const Status st = openFrameSource(spec, args.get("camera"), &source);
    if (!st.ok()) return fail(st.message());
    if (auto* synth = dynamic_cast<SyntheticSource*>(source.get())) scene = &synth->scene();
  }

  SessionOptions options;
  setLineOptions(int(line_samples), !args.has("no-lines"), &options.system);
  options.system.output_delay_frames = int(output_delay);
  options.trajectory_path = args.get("out");
  options.covariance_path = args.get("covariance");
  options.max_frames = max_frames;
  options.rss_every = rss_every;
  options.progress = args.has("progress");
  options.trace = args.has("trace");
  options.use_stages = args.has("mode");
  options.staged = staged;
  options.count_allocations = args.has("count-allocations");
  // Only the ATE needs the poses in memory. A memory-profiling run (--rss-every) keeps nothing
  // per frame, so its resident size can stay flat; it reports no ATE for synthetic scenes.
  options.keep_trajectory = args.has("gt") || (scene != nullptr && rss_every == 0);

  SessionResult result;
  Status st = runSession(*source, options, &result);
  if (!st.ok()) return fail(st.message());

  double ate = -1;
  std::vector<StampedPose> ground_truth;
  if (args.has("gt")) {
    st = readTumTrajectory(args.get("gt"), &ground_truth).withContext("reading ground truth");
    if (!st.ok()) return fail(st.message());
  } else if (scene != nullptr) {
    ground_truth = syntheticGroundTruth(*scene, result.frames + result.frames_dropped);
  }
  if (!ground_truth.empty() && options.keep_trajectory) {
    st = ateRmse(ground_truth, result.trajectory, &ate);
    if (!st.ok()) std::fprintf(stderr, "plumb run: no ATE: %s\n", st.message().c_str());
  }

  const OdometryStats& s = result.stats;
  std::printf("frames %ld: ok %llu, weak %llu, lost %llu, not initialized %llu; keyframes %llu, "
              "relocalizations %llu, map segments %llu\n",
              result.frames, (unsigned long long)s.frames_ok, (unsigned long long)s.frames_weak,
              (unsigned long long)s.frames_lost, (unsigned long long)s.frames_not_initialized,
              (unsigned long long)s.keyframes, (unsigned long long)s.relocalizations,
              (unsigned long long)s.segments);
  std::printf("ms per frame: mean %.2f, p99 %.2f (extract %.2f, track %.2f, map %.2f mean)\n",
              result.total_ms.mean(), result.total_ms.percentile(99), result.extract_ms.mean(),
              result.track_ms.mean(), result.map_ms.mean());
  if (options.use_stages) {
    // Extraction runs on its own stage there, so the per-frame extract time above reads 0.
    const runtime::RunReport& report = result.staged.report;
    std::printf("staged %s: %.1f frames/s, dropped %llu, late %llu, extraction failures %llu\n",
                runtime::runModeName(options.staged.mode), report.framesPerSecond(),
                (unsigned long long)report.frames_dropped, (unsigned long long)report.frames_late,
                (unsigned long long)result.staged.extraction_failures);
  }
  if (options.count_allocations) {
    if (result.allocation_frames == 0) {
      std::printf("allocations: run not longer than the %llu-frame warm-up\n",
                  (unsigned long long)options.staged.warmup_frames);
    } else {
      std::printf("allocations after warm-up: %llu over %llu frames (%.2f per frame)\n",
                  (unsigned long long)result.allocations_after_warmup, (unsigned long long)result.allocation_frames,
                  double(result.allocations_after_warmup) / double(result.allocation_frames));
    }
  }
  if (ate >= 0) std::printf("ATE RMSE %.4f m\n", ate);
  if (args.has("stats")) {
    std::FILE* f = std::fopen(args.get("stats").c_str(), "w");
    if (f == nullptr) return fail(args.get("stats") + ": cannot open for writing");
    const std::string json = sessionJson(result, options, ate);
    const bool written = std::fwrite(json.data(), 1, json.size(), f) == json.size();
    if (std::fclose(f) != 0 || !written) return fail(args.get("stats") + ": write failed");
  }
  return 0;
}

}  // namespace
}  // namespace plumb::tools

PLUMB_COMMAND(run, "odometry over a dataset or synthetic scene: trajectory, covariances, stats, ATE",
              plumb::tools::runRun);
