// plumb demo: the odometry system on the built-in synthetic scenes (rendered in memory, Kinect-like
// depth noise, exact ground truth): ATE RMSE and ms per frame, and on the low-texture scene the
// paper's comparison of point + line guidance features against points only.
#include <cstdio>
#include <memory>
#include <string>

#include "tools/args.h"
#include "tools/command.h"
#include "tools/odometry_session.h"

namespace plumb::tools {
namespace {

void printDemoUsage() {
  std::printf(
      "usage: plumb demo [--frames N] [--seed S] [--line-samples N]\n"
      "  Renders the synthetic scenes 'textured' and 'low_texture' with Kinect-like noise (depth\n"
      "  sigma 0.0014 z^2, holes at depth edges, 1 grey level of pixel noise), runs the odometry\n"
      "  (single thread), prints ATE RMSE and ms per frame; low_texture also with --no-lines.\n"
      "  --frames N        frames per scene (default 600)\n"
      "  --seed S          scene seed (default 1)\n"
      "  --line-samples N  line-guidance points per line (default 5)\n");
}

struct DemoRun {
  const char* preset;
  bool lines;
};

int runDemo(int argc, char** argv) {
  Args args(argc, argv, {"frames", "seed", "line-samples"}, {});
  if (args.help()) {
    printDemoUsage();
    return 0;
  }
  if (!args.error().empty() || !args.positional().empty()) {
    std::fprintf(stderr, "plumb demo: %s\n",
                 args.error().empty() ? ("unexpected argument " + args.positional()[0]).c_str() : args.error().c_str());
    printDemoUsage();
    return 2;
  }
  bool ok = true;
  const long frames = args.getInt("frames", 600, &ok);
  const long seed = args.getInt("seed", 1, &ok);
  const long line_samples = args.getInt("line-samples", 5, &ok);
  if (!ok || frames <= 0 || seed < 0 || line_samples < 0 || line_samples > long(kMaxLineSamples)) {
    std::fprintf(stderr, "plumb demo: --frames > 0, --seed >= 0, --line-samples 0..%zu\n", kMaxLineSamples);
    return 2;
  }

  std::printf("%-12s %-12s %7s %7s %10s %9s %9s %6s\n", "scene", "features", "frames", "lost", "ATE [m]",
              "ms mean", "ms p99", "KFs");
  const DemoRun runs[] = {{"textured", true}, {"low_texture", true}, {"low_texture", false}};
  for (const DemoRun& run : runs) {
    SynthOptions synth;
    synth.preset = run.preset;
    synth.seed = uint64_t(seed);
    synth.frames = int(frames);
    enableKinectNoise(&synth);
    std::unique_ptr<SyntheticSource> source;
    Status st = SyntheticSource::create(synth, &source);
    if (!st.ok()) {
      std::fprintf(stderr, "plumb demo: %s\n", st.message().c_str());
      return 1;
    }
    SessionOptions options;
    setLineOptions(int(line_samples), run.lines, &options.system);
    SessionResult result;
    st = runSession(*source, options, &result);
    if (!st.ok()) {
      std::fprintf(stderr, "plumb demo: %s: %s\n", run.preset, st.message().c_str());
      return 1;
    }
    double ate = -1;
    st = ateRmse(syntheticGroundTruth(source->scene(), result.frames), result.trajectory, &ate);
    if (!st.ok()) std::fprintf(stderr, "plumb demo: %s: no ATE: %s\n", run.preset, st.message().c_str());
    std::printf("%-12s %-12s %7ld %7llu %10.4f %9.2f %9.2f %6llu\n", run.preset,
                run.lines ? "points+lines" : "points", result.frames,
                (unsigned long long)(result.stats.frames_lost + result.stats.frames_not_initialized), ate,
                result.total_ms.mean(), result.total_ms.percentile(99), (unsigned long long)result.stats.keyframes);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace
}  // namespace plumb::tools

PLUMB_COMMAND(demo, "odometry on the built-in synthetic scenes: ATE and ms per frame, lines on/off",
              plumb::tools::runDemo);
