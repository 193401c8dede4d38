// plumb demo: the odometry system on the built-in synthetic scenes (rendered in memory, Kinect-like
// depth noise, exact ground truth): ATE RMSE and ms per frame, and on the low-texture scene the
// paper's comparison of point + line guidance features against points only.
#include <climits>
#include <cstdio>
#include <memory>
#include <string>

#include "tools/args.h"
#include "tools/command.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/trajectory/evaluate.h"
#include "tools/run_outputs.h"

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
  long long frames = 600, seed = 1, line_samples = 5;
  Status parsed = args.integer("frames", 1, 10'000'000, &frames);
  if (parsed.ok()) parsed = args.integer("seed", 0, LLONG_MAX, &seed);
  if (parsed.ok()) parsed = args.integer("line-samples", 0, long(kMaxLineSamples), &line_samples);
  if (parsed.ok() && line_samples == 1) parsed = Status::Error("--line-samples takes 0 or 2..10 (1 point is not a line)");
  if (!parsed.ok()) {
    std::fprintf(stderr, "plumb demo: %s\n", parsed.message().c_str());
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
    SystemOptions system_options;
    setLineSamples(int(line_samples), run.lines, &system_options.odometry);
    RunOutputOptions output_options;
    output_options.expected_frames = source->frameCount();
    RunOutputs outputs(output_options);
    RunRecord record;
    st = runToOutputs(*source, system_options, OdometryRunOptions{}, outputs, &record);
    if (!st.ok()) {
      std::fprintf(stderr, "plumb demo: %s: %s\n", run.preset, st.message().c_str());
      return 1;
    }
    AteResult ate;
    st = evaluateAte(syntheticGroundTruth(source->scene(), long(outputs.statistics().frames())), outputs.trajectory(),
                     AteOptions{}, &ate);
    if (!st.ok()) std::fprintf(stderr, "plumb demo: %s: no ATE: %s\n", run.preset, st.message().c_str());
    const runtime::LatencyHistogram& total = outputs.statistics().totalNs();
    std::printf("%-12s %-12s %7llu %7llu %10.4f %9.2f %9.2f %6llu\n", run.preset,
                run.lines ? "points+lines" : "points", (unsigned long long)outputs.statistics().frames(),
                (unsigned long long)(record.odometry.frames_lost + record.odometry.frames_not_initialized),
                st.ok() ? ate.translation_m.rmse : -1.0, total.meanNs() * 1e-6,
                double(total.percentileNs(0.99)) * 1e-6, (unsigned long long)record.odometry.keyframes);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace
}  // namespace plumb::tools

PLUMB_COMMAND(demo, "odometry on the built-in synthetic scenes: ATE and ms per frame, lines on/off",
              plumb::tools::runDemo);
