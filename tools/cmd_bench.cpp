// plumb bench frontend: per-frame cost of the measurement front end (ORB, lines + LBD, depth +
// line-guidance sampling) on a TUM-layout sequence, single thread. Prints median / p99 per stage;
// the last line is the machine-readable summary:
//   frontend_ms_median X
// The comparison with the stock OpenCV path (cv::ORB + line_descriptor) is the separate program
// build/bin/plumb_bench_stock_frontend (bench/frontend/), so that `plumb` does not link
// features2d and line_descriptor (docs/EMBEDDED.md).
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "drivers/dataset/camera_presets.h"
#include "drivers/dataset/tum_dataset.h"
#include "pipeline/frontend/depth_registration.h"
#include "pipeline/frontend/feature_extractor.h"
#include "platform/stage_timing.h"
#include "tools/args.h"
#include "tools/command.h"

namespace plumb::tools {
namespace {

constexpr int kNameWidth = 24;

void printUsage() {
  std::printf(
      "usage: plumb bench frontend --dataset DIR [--camera tum1] [--frames N]\n"
      "                            [--line-level L] [--line-samples N] [--opencv-lsd] [--clock wall|cpu]\n"
      "                            [--dump FILE] [--repeat N]\n"
      "  Runs the front end (pipeline/frontend/feature_extractor.h) with default ExtractorOptions on every\n"
      "  frame of a TUM-layout folder, single thread. The stock OpenCV comparison (cv::ORB +\n"
      "  line_descriptor) is build/bin/plumb_bench_stock_frontend --dataset DIR (bench/frontend/).\n"
      "  --clock: what the summary line reports: wall (steady clock, default) or cpu (this\n"
      "  thread's CPU time, which does not count waiting for a core on a loaded machine).\n"
      "  --dump: write every extracted feature (keypoints, descriptors, lines, samples) as text, so\n"
      "  a speed change can be checked to leave the output bit-identical (diff two dumps).\n"
      "  --repeat: extract every frame N times and keep, per stage, the fastest run (for A/B\n"
      "  comparisons on a loaded machine; the default 1 is the honest single-run number).\n");
}

// One line per feature, floats as hex so "identical" means bit-identical.
void dumpFeatures(std::FILE* f, size_t frame, const FrameFeatures& features) {
  std::fprintf(f, "frame %zu keypoints %zu lines %zu\n", frame, features.keypoints.size(), features.lines.size());
  for (size_t i = 0; i < features.keypoints.size(); ++i) {
    const KeypointObservation& k = features.keypoints[i];
    const Descriptor256& d = features.keypoint_descriptors[i];
    std::fprintf(f, "k %a %a %a %a %a %a %d %a %016llx%016llx%016llx%016llx\n", k.px.x(), k.px.y(), k.px_undist.x(),
                 k.px_undist.y(), k.angle_deg, k.response, k.octave, k.depth_m, (unsigned long long)d.words[0],
                 (unsigned long long)d.words[1], (unsigned long long)d.words[2], (unsigned long long)d.words[3]);
  }
  for (size_t i = 0; i < features.lines.size(); ++i) {
    const LineObservation& l = features.lines[i];
    const Descriptor256& d = features.line_descriptors[i];
    std::fprintf(f, "l %a %a %a %a %a %a %a %d %a %d %d %016llx%016llx%016llx%016llx", l.start_px.x(), l.start_px.y(),
                 l.end_px.x(), l.end_px.y(), l.l.x(), l.l.y(), l.l.z(), l.octave, l.response, l.num_samples, l.has_3d,
                 (unsigned long long)d.words[0], (unsigned long long)d.words[1], (unsigned long long)d.words[2],
                 (unsigned long long)d.words[3]);
    for (int s = 0; s < l.num_samples; ++s) {
      std::fprintf(f, " %a %a %a", l.sample_P_cam[s].x(), l.sample_P_cam[s].y(), l.sample_P_cam[s].z());
    }
    std::fprintf(f, "\n");
  }
}

int benchFrontend(int argc, char** argv) {
  Args args(argc, argv, {"dataset", "camera", "frames", "line-level", "line-samples", "clock", "dump", "repeat"}, {"no-stock", "opencv-lsd"});
  if (args.help()) { printUsage(); return 0; }
  if (!args.error().empty() || !args.has("dataset")) {
    std::fprintf(stderr, "plumb bench frontend: %s\n", args.error().empty() ? "--dataset is required" : args.error().c_str());
    printUsage();
    return 2;
  }
  bool ok = true;
  const long max_frames = args.getInt("frames", -1, &ok);
  const long repeat = args.getInt("repeat", 1, &ok);
  if (!ok || repeat < 1) { std::fprintf(stderr, "plumb bench frontend: --frames and --repeat need integers (repeat >= 1)\n"); return 2; }
  PinholeCamera camera;
  Status st = cameraFromSpec(args.get("camera", "tum1"), &camera);
  std::unique_ptr<TumDatasetSource> source;
  if (st.ok()) st = TumDatasetSource::open(args.get("dataset"), camera, &source);
  if (!st.ok()) { std::fprintf(stderr, "plumb bench frontend: %s\n", st.message().c_str()); return 1; }

  cv::setNumThreads(1);  // single thread, for both paths
  ExtractorOptions options;
  long long line_level = options.line_level, line_samples = options.line_samples;
  ok = args.integer("line-level", 0, options.num_levels - 1, &line_level).ok() &&
       args.integer("line-samples", 0, long(kMaxLineSamples), &line_samples).ok() && ok;
  options.line_level = int(line_level);
  options.line_samples = int(line_samples);
  options.use_opencv_lsd = args.has("opencv-lsd");
  const std::string clock = args.get("clock", "wall");
  if (clock != "wall" && clock != "cpu") {
    std::fprintf(stderr, "plumb bench frontend: --clock must be wall or cpu\n");
    return 2;
  }
  if (!ok || options.line_samples < 0 || options.line_samples > static_cast<int>(kMaxLineSamples) ||
      options.line_level < 0 || options.line_level >= options.num_levels) {
    std::fprintf(stderr, "plumb bench frontend: --line-level must be 0..%d, --line-samples 0..%zu\n",
                 options.num_levels - 1, kMaxLineSamples);
    return 2;
  }
  FeatureExtractor extractor(camera, options);
  // A camera file with an unregistered depth camera: each frame's depth is registered first (the
  // pipeline's register stage), timed on its own.
  DepthRegistration registration(camera);
  cv::Mat registered_depth;
  auto features = std::make_unique<FrameFeatures>();
  std::FILE* dump = nullptr;
  if (args.has("dump")) {
    dump = std::fopen(args.get("dump").c_str(), "w");
    if (dump == nullptr) { std::fprintf(stderr, "plumb bench frontend: cannot write %s\n", args.get("dump").c_str()); return 1; }
  }

  TimingSeries orb{"ORB", {}}, lines{"lines + LBD", {}}, depth{"depth + sampling", {}}, total{"frontend total", {}};
  TimingSeries cpu_orb{"ORB (CPU)", {}}, cpu_lines{"lines + LBD (CPU)", {}}, cpu_depth{"depth + sampling (CPU)", {}};
  TimingSeries cpu_total{"frontend total (CPU)", {}};
  TimingSeries registering{"depth registration", {}}, cpu_registering{"depth registration (CPU)", {}};
  double sum_kp = 0, sum_kp_depth = 0, sum_lines = 0, sum_lines3d = 0;
  RgbdImage frame;
  const size_t n = max_frames > 0 ? std::min<size_t>(source->size(), max_frames) : source->size();
  for (size_t i = 0; i < n; ++i) {
    st = source->load(i, frame);
    if (!st.ok()) { std::fprintf(stderr, "plumb bench frontend: %s\n", st.message().c_str()); return 1; }
    if (registration.active()) {
      const auto start = StageClock::now();
      const double cpu_start = threadCpuMs();
      if (!registration.registerInto(frame.depth_raw, frame.depth_factor, registered_depth)) {
        std::fprintf(stderr, "plumb bench frontend: frame %zu does not match the depth camera\n", i);
        return 1;
      }
      registering.ms.push_back(msSince(start));
      cpu_registering.ms.push_back(threadCpuMs() - cpu_start);
    }
    ExtractorTimings t;
    for (long r = 0; r < repeat; ++r) {
      const cv::Mat& depth = registration.active() ? registered_depth : frame.depth_raw;
      if (!extractor.extract(frame.bgr, depth, frame.depth_factor, *features)) {
        std::fprintf(stderr, "plumb bench frontend: frame %zu does not match the camera size\n", i);
        return 1;
      }
      const ExtractorTimings& last = extractor.lastTimings();
      if (r == 0) {
        t = last;
        continue;
      }
      t.orb_ms = std::min(t.orb_ms, last.orb_ms);
      t.lines_ms = std::min(t.lines_ms, last.lines_ms);
      t.depth_ms = std::min(t.depth_ms, last.depth_ms);
      t.total_ms = std::min(t.total_ms, last.total_ms);
      t.orb_cpu_ms = std::min(t.orb_cpu_ms, last.orb_cpu_ms);
      t.lines_cpu_ms = std::min(t.lines_cpu_ms, last.lines_cpu_ms);
      t.depth_cpu_ms = std::min(t.depth_cpu_ms, last.depth_cpu_ms);
      t.total_cpu_ms = std::min(t.total_cpu_ms, last.total_cpu_ms);
    }
    if (dump != nullptr) dumpFeatures(dump, i, *features);
    orb.ms.push_back(t.orb_ms);
    lines.ms.push_back(t.lines_ms);
    depth.ms.push_back(t.depth_ms);
    total.ms.push_back(t.total_ms);
    cpu_total.ms.push_back(t.total_cpu_ms);
    cpu_orb.ms.push_back(t.orb_cpu_ms);
    cpu_lines.ms.push_back(t.lines_cpu_ms);
    cpu_depth.ms.push_back(t.depth_cpu_ms);
    sum_kp += t.num_keypoints;
    sum_kp_depth += t.num_keypoints_with_depth;
    sum_lines += t.num_lines;
    sum_lines3d += t.num_lines_3d;
  }
  if (dump != nullptr) std::fclose(dump);
  const double frames = std::max<size_t>(n, 1);
  std::printf("plumb bench frontend: %zu frames of %s, 1 thread\n", n, args.get("dataset").c_str());
  std::printf("  per frame: %.0f keypoints (%.0f with depth), %.0f lines (%.0f with a 3D fit, %d samples max)\n",
              sum_kp / frames, sum_kp_depth / frames, sum_lines / frames, sum_lines3d / frames, options.line_samples);
  orb.print(kNameWidth);
  lines.print(kNameWidth);
  depth.print(kNameWidth);
  total.print(kNameWidth);
  cpu_orb.print(kNameWidth);
  cpu_lines.print(kNameWidth);
  cpu_depth.print(kNameWidth);
  cpu_total.print(kNameWidth);
  if (registration.active()) {
    registering.print(kNameWidth);
    cpu_registering.print(kNameWidth);
  }
  std::printf("  stock OpenCV comparison (cv::ORB + line_descriptor): build/bin/plumb_bench_stock_frontend\n"
              "  --dataset %s (a separate program, so that plumb does not link those libraries)\n",
              args.get("dataset").c_str());
  const bool cpu = clock == "cpu";
  std::printf("summary clock: %s\n", cpu ? "thread CPU time" : "wall (steady clock)");
  std::printf("frontend_ms_median %.2f\n", (cpu ? cpu_total : total).percentile(0.5));
  return 0;
}

int benchMain(int argc, char** argv) {
  if (argc >= 1 && std::string(argv[0]) == "frontend") return benchFrontend(argc - 1, argv + 1);
  std::fprintf(stderr, "usage: plumb bench frontend --dataset DIR   (the only benchmark so far)\n");
  return argc >= 1 && (std::string(argv[0]) == "--help" || std::string(argv[0]) == "-h") ? 0 : 2;
}

}  // namespace

PLUMB_COMMAND(bench, "benchmarks: `plumb bench frontend --dataset DIR` (front end; instructions per stage: bench/instructions/)", benchMain);

}  // namespace plumb::tools
