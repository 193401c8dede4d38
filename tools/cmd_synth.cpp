// plumb synth: write a seeded synthetic RGB-D scene in TUM layout (drivers/synth).
#include <chrono>
#include <filesystem>
#include <cstdio>

#include "drivers/synth/synthetic_scene.h"
#include "tools/args.h"
#include "tools/command.h"

namespace {

void printHelp() {
  std::printf(
      "usage: plumb synth --out DIR [options]\n"
      "Writes a synthetic indoor RGB-D sequence with exact ground truth in TUM layout\n"
      "(rgb/ depth/ rgb.txt depth.txt associations.txt groundtruth.txt camera.txt).\n"
      "Same options -> byte-identical folder.\n\n"
      "  --out DIR            output folder (created if missing)\n"
      "  --preset NAME        textured | low_texture | fast_rotation (default textured)\n"
      "  --seed N             layout, textures, path phases and noise (default 1)\n"
      "  --frames N           frames to write (default 300 = 10 s)\n"
      "  --fps F              frame rate (default 30)\n"
      "  --loop-period S      seconds per lap of the closed camera path (default 20)\n"
      "  --pixel-noise S      Gaussian colour noise, grey levels (default 0)\n"
      "  --depth-noise        Kinect-like depth noise, sigma = k z^2\n"
      "  --depth-noise-k K    k in 1/m (default 0.0014)\n"
      "  --holes              no depth on the far side of depth edges\n"
      "  --depth-camera offset|offset-qvga\n"
      "                       depth from a depth camera beside the colour camera, NOT registered to\n"
      "                       it (2.5 cm baseline, 0.5 deg, other intrinsics; offset-qvga: 320x240);\n"
      "                       camera.txt describes it, so plumb registers the depth (docs/SYNTHETIC.md)\n");
}

int runSynth(int argc, char** argv) {
  const plumb::tools::Args args(argc, argv,
                                {"out", "preset", "seed", "frames", "fps", "loop-period", "pixel-noise",
                                 "depth-noise-k", "depth-camera"},
                                {"depth-noise", "holes"});
  if (args.help()) {
    printHelp();
    return 0;
  }
  if (!args.error().empty()) {
    std::fprintf(stderr, "plumb synth: %s (see plumb synth --help)\n", args.error().c_str());
    return 2;
  }
  if (!args.has("out") || !args.positional().empty()) {
    std::fprintf(stderr, "plumb synth: need --out DIR and no positional arguments (see plumb synth --help)\n");
    return 2;
  }
  plumb::SynthOptions options;
  // Each numeric option is parsed on its own so that an error names it.
  std::string malformed;
  auto number = [&](const char* key, double fallback) {
    bool ok = true;
    const double value = args.getDouble(key, fallback, &ok);
    if (!ok && malformed.empty()) malformed = key;
    return value;
  };
  auto integer = [&](const char* key, long fallback) {
    bool ok = true;
    const long value = args.getInt(key, fallback, &ok);
    if (!ok && malformed.empty()) malformed = key;
    return value;
  };
  options.preset = args.get("preset", options.preset);
  const long seed = integer("seed", 1);
  const long frames = integer("frames", options.frames);
  options.frames = frames > 100000000L ? -1 : static_cast<int>(frames);  // absurd counts fail validate()
  options.fps = number("fps", options.fps);
  options.loop_period_s = number("loop-period", options.loop_period_s);
  options.pixel_noise_sigma = number("pixel-noise", options.pixel_noise_sigma);
  options.depth_noise_k = number("depth-noise-k", options.depth_noise_k);
  options.depth_noise = args.has("depth-noise");
  options.depth_edge_holes = args.has("holes");
  if (!malformed.empty()) {
    std::fprintf(stderr, "plumb synth: --%s '%s' is not a number\n", malformed.c_str(), args.get(malformed).c_str());
    return 2;
  }
  if (seed < 0) {
    std::fprintf(stderr, "plumb synth: --seed must be a non-negative integer\n");
    return 2;
  }
  options.seed = static_cast<uint64_t>(seed);
  if (args.has("depth-camera")) {
    const std::string which = args.get("depth-camera");
    if (which != "offset" && which != "offset-qvga") {
      std::fprintf(stderr, "plumb synth: --depth-camera takes offset or offset-qvga, not '%s'\n", which.c_str());
      return 2;
    }
    options.depth_camera = which == "offset" ? plumb::synthOffsetDepthCamera() : plumb::synthOffsetDepthCameraQvga();
  }

  // A dataset is never written over another: an existing folder must be empty.
  const std::string out_dir = args.get("out");
  std::error_code ec;
  if (std::filesystem::exists(out_dir, ec) &&
      (!std::filesystem::is_directory(out_dir, ec) || !std::filesystem::is_empty(out_dir, ec))) {
    std::fprintf(stderr, "plumb synth: --out %s exists and is not an empty folder: refusing to write a dataset over it\n",
                 out_dir.c_str());
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  const plumb::Status status = plumb::writeSynthDataset(options, out_dir);
  if (!status.ok()) {
    std::fprintf(stderr, "plumb: %s\n", status.message().c_str());  // messages name "synth:" or the file
    return 1;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %d frames (%s, seed %llu) to %s in %.1f s\n", options.frames, options.preset.c_str(),
              static_cast<unsigned long long>(options.seed), args.get("out").c_str(), seconds);
  return 0;
}

}  // namespace

PLUMB_COMMAND(synth, "write a seeded synthetic RGB-D scene in TUM layout", runSynth);
