// plumb eval: ATE and RPE of an estimated trajectory against ground truth, by the TUM benchmark's
// conventions (drivers/trajectory/evaluate.h), optionally with a PNG plot.
#include <cstdio>
#include <string>

#include "drivers/synth/synth_spec.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/trajectory/trajectory_io.h"
#include "drivers/trajectory/trajectory_plot.h"
#include "runtime/json_text.h"
#include "tools/args.h"
#include "tools/command.h"
#include "tools/eval_loops.h"
#include "tools/eval_nees.h"
#include "tools/io_plan.h"

namespace plumb::tools {
namespace {

void printEvalUsage() {
  std::printf(
      "usage: plumb eval --gt GT.txt --est EST.txt [--plot out.png] [--json]\n"
      "                  [--covariance COV --nees] [--track-covariance TCOV]\n"
      "       plumb eval --gt GT.txt --loops STATS.json [--json]\n"
      "  Trajectories in TUM format (timestamp tx ty tz qx qy qz qw, T_world_cam); --gt may also\n"
      "  name a synthetic scene, synth:PRESET[:SEED[:FRAMES]], for its exact ground truth.\n"
      "  ATE: greedy unique association |dt| < 0.02 s, rigid alignment (no scale), RMSE in m.\n"
      "  RPE: pairs ~1 s apart (benchmark evaluate_rpe, fixed delta 1 s): m/s and deg/s.\n"
      "  --plot  write a PNG: top view of ground truth vs aligned estimate, x/y/z error over time\n"
      "  --json  print one JSON object instead of text\n"
      "  --nees  NEES per dof of the published covariances against ground truth (docs/UNCERTAINTY.md):\n"
      "          --covariance: a `plumb run --covariance` (keyframe-to-keyframe relative poses) or\n"
      "          `--track-covariance` file (tracked poses, frame-to-frame motion; gauge: the first\n"
      "          pose of --est); --track-covariance: the second file. JSON key nees_per_dof.\n"
      "  --loops grade the loop audit of `plumb run --stats STATS.json`: each accepted loop's error,\n"
      "          loop precision and recall over the revisits of the ground truth (docs/LOOP.md)\n");
}

Status readTrajectory(const char* role, const std::string& path, std::vector<StampedPose>* poses,
                      TrajectoryReadReport* report) {
  if (isSynthSpec(path)) {  // exact ground truth of a synthetic scene, e.g. --gt synth:loop:3
    SynthOptions options;
    std::unique_ptr<SyntheticScene> scene;
    Status st = parseSynthSpec(path, &options);
    if (st.ok()) st = SyntheticScene::create(options, &scene);
    if (st.ok()) *poses = syntheticGroundTruth(*scene, options.frames);
    return st.withContext(std::string("reading ") + role);
  }
  return readTumTrajectory(path, poses, {}, report).withContext(std::string("reading ") + role);
}

void printJson(const std::string& gt, const std::string& est, const AteResult& ate, const RpeResult* rpe,
               const std::string& plot, const NeesResult* nees) {
  // Numbers that are not finite (e.g. an overflow on absurd input) print as null: valid JSON.
  using runtime::jsonNumber;
  const auto quoted = runtime::jsonString;
  std::printf("{\"ground_truth\": %s, \"estimate\": %s,\n", quoted(gt).c_str(), quoted(est).c_str());
  const ErrorStatistics& a = ate.translation_m;
  std::printf(" \"ate\": {\"pairs\": %zu, \"rmse_m\": %s, \"mean_m\": %s, \"median_m\": %s, \"max_m\": %s},\n",
              ate.pairs, jsonNumber(a.rmse).c_str(), jsonNumber(a.mean).c_str(), jsonNumber(a.median).c_str(),
              jsonNumber(a.max).c_str());
  if (rpe) {
    std::printf(
        " \"rpe\": {\"pairs\": %zu, \"delta_s\": 1.0, \"translation_rmse_m_per_s\": %s, "
        "\"translation_mean_m_per_s\": %s, \"rotation_rmse_deg_per_s\": %s, \"rotation_mean_deg_per_s\": %s}",
        rpe->pairs, jsonNumber(rpe->translation_m_per_s.rmse).c_str(), jsonNumber(rpe->translation_m_per_s.mean).c_str(),
        jsonNumber(rpe->rotation_deg_per_s.rmse).c_str(), jsonNumber(rpe->rotation_deg_per_s.mean).c_str());
  } else {
    std::printf(" \"rpe\": null");
  }
  std::printf(",\n \"plot\": %s", plot.empty() ? "null" : quoted(plot).c_str());
  if (nees) std::printf(",\n%s", neesJsonMembers(*nees).c_str());
  std::printf("}\n");
}

void printText(const AteResult& ate, const RpeResult* rpe, const std::string& rpe_note) {
  const ErrorStatistics& a = ate.translation_m;
  std::printf("ATE RMSE %.4f m over %zu pairs (mean %.4f, median %.4f, max %.4f m)\n", a.rmse, ate.pairs,
              a.mean, a.median, a.max);
  if (rpe) {
    std::printf("RPE translation RMSE %.4f m/s, rotation RMSE %.4f deg/s over %zu pairs (delta 1 s)\n",
                rpe->translation_m_per_s.rmse, rpe->rotation_deg_per_s.rmse, rpe->pairs);
  } else {
    std::printf("RPE not available: %s\n", rpe_note.c_str());
  }
}

int runEval(int argc, char** argv) {
  Args args(argc, argv, {"gt", "est", "plot", "loops", "covariance", "track-covariance"}, {"json", "nees"});
  if (args.help()) {
    printEvalUsage();
    return 0;
  }
  const bool loops = args.has("loops");
  if (!args.error().empty() || !args.positional().empty() || !args.has("gt") || args.has("est") == loops ||
      (loops && args.has("plot"))) {
    std::fprintf(stderr, "plumb eval: %s\n",
                 !args.error().empty()        ? args.error().c_str()
                 : loops                      ? "--loops grades a --stats file alone (no --est or --plot)"
                 : !args.positional().empty() ? ("unexpected argument " + args.positional()[0]).c_str()
                                              : "--gt and --est (or --loops alone) are required");
    printEvalUsage();
    return 2;
  }
  if (args.has("nees") != (args.has("covariance") || args.has("track-covariance"))) {
    std::fprintf(stderr, "plumb eval: --nees needs --covariance and/or --track-covariance, and they need --nees\n");
    return 2;
  }
  const std::string gt_path = args.get("gt"), est_path = args.get("est"), plot_path = args.get("plot");
  if (loops) {  // reads the ground truth and the statistics, writes nothing
    std::vector<StampedPose> ground_truth;
    TrajectoryReadReport report;
    const Status st = readTrajectory("ground truth", gt_path, &ground_truth, &report);
    if (!st.ok()) {
      std::fprintf(stderr, "plumb eval: %s\n", st.message().c_str());
      return 1;
    }
    return evalLoops(ground_truth, args.get("loops"), args.has("json"));
  }
  // The plot never overwrites an input (the ground truth, the estimate, a link to either), and
  // its folder must take it: checked before anything is read.
  IoPlan io;
  if (!isSynthSpec(gt_path)) io.addInput(gt_path);
  io.addInput(est_path);
  io.addInput(args.get("covariance"));
  io.addInput(args.get("track-covariance"));
  io.addOutput("--plot", plot_path);
  const Status io_status = io.check();
  if (!io_status.ok()) {
    std::fprintf(stderr, "plumb eval: %s\n", io_status.message().c_str());
    return 2;
  }
  std::vector<StampedPose> ground_truth, estimate;
  TrajectoryReadReport gt_report, est_report;
  for (const Status& st : {readTrajectory("ground truth", gt_path, &ground_truth, &gt_report),
                           readTrajectory("estimate", est_path, &estimate, &est_report)}) {
    if (!st.ok()) {
      std::fprintf(stderr, "plumb eval: %s\n", st.message().c_str());
      return 1;
    }
  }
  // Not silent: the benchmark keeps the later of two equal stamps, we say that we did too.
  if (gt_report.duplicate_timestamps_replaced + est_report.duplicate_timestamps_replaced > 0)
    std::fprintf(stderr, "plumb eval: note: %d duplicate timestamp(s) in %s, %d in %s; kept the later line\n",
                 gt_report.duplicate_timestamps_replaced, gt_path.c_str(),
                 est_report.duplicate_timestamps_replaced, est_path.c_str());

  AteResult ate;
  Status st = evaluateAte(ground_truth, estimate, {}, &ate);
  if (!st.ok()) {
    std::fprintf(stderr, "plumb eval: %s vs %s: %s\n", est_path.c_str(), gt_path.c_str(),
                 st.message().c_str());
    return 1;
  }
  // A short estimate (< 1 s) has no RPE pairs: report that, ATE is still meaningful.
  RpeResult rpe;
  const Status rpe_status = evaluateRpe(ground_truth, estimate, {}, &rpe);

  if (!plot_path.empty()) {
    TrajectoryPlotOptions plot_options;
    char title[160];
    std::snprintf(title, sizeof(title), "ATE RMSE %.4f m over %zu pairs", ate.translation_m.rmse, ate.pairs);
    plot_options.title = title;
    st = writeTrajectoryPlot(plot_path, ate, plot_options);
    if (!st.ok()) {
      std::fprintf(stderr, "plumb eval: %s\n", st.message().c_str());
      return 1;
    }
  }
  NeesResult nees;
  if (args.has("nees")) {
    std::vector<std::string> paths;
    for (const char* key : {"covariance", "track-covariance"}) {
      if (args.has(key)) paths.push_back(args.get(key));
    }
    st = evaluateNeesFiles(ground_truth, estimate, paths, &nees);
    if (!st.ok()) {
      std::fprintf(stderr, "plumb eval: %s\n", st.message().c_str());
      return 1;
    }
  }
  if (args.has("json")) {
    printJson(gt_path, est_path, ate, rpe_status.ok() ? &rpe : nullptr, plot_path, args.has("nees") ? &nees : nullptr);
  } else {
    printText(ate, rpe_status.ok() ? &rpe : nullptr, rpe_status.message());
    if (!plot_path.empty()) std::printf("plot: %s\n", plot_path.c_str());
    if (args.has("nees")) printNeesText(nees);
  }
  return 0;
}

}  // namespace
}  // namespace plumb::tools

PLUMB_COMMAND(eval, "ATE/RPE of an estimated trajectory against ground truth (TUM format)",
              plumb::tools::runEval);
