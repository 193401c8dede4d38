#include "drivers/synth/synth_spec.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "drivers/common/text_lines.h"

namespace plumb {
namespace {

constexpr const char* kSynthPrefix = "synth:";

std::vector<std::string> splitColons(const std::string& text) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t colon; (colon = text.find(':', start)) != std::string::npos; start = colon + 1)
    parts.push_back(text.substr(start, colon - start));
  parts.push_back(text.substr(start));
  return parts;
}

}  // namespace

bool isSynthSpec(const std::string& spec) { return spec.rfind(kSynthPrefix, 0) == 0; }

Status parseSynthSpec(const std::string& spec, SynthOptions* options) {
  if (!isSynthSpec(spec)) return Status::Error(spec + ": not a synth:PRESET[:SEED[:FRAMES]] source");
  const std::vector<std::string> parts = splitColons(spec.substr(std::string(kSynthPrefix).size()));
  if (parts.size() > 3 || parts[0].empty()) return Status::Error(spec + ": expected synth:PRESET[:SEED[:FRAMES]]");
  options->preset = parts[0];
  // No count given: the preset's own length (two laps for "loop", the corridor for "repeated").
  if (presetDefaultFrames(parts[0]) > 0) options->frames = presetDefaultFrames(parts[0]);
  if (parts.size() > 1) {
    double seed = 0;
    if (!parseDouble(parts[1], &seed) || seed < 0 || seed != static_cast<double>(static_cast<uint64_t>(seed)))
      return Status::Error(spec + ": seed '" + parts[1] + "' is not a non-negative integer");
    options->seed = static_cast<uint64_t>(seed);
  }
  if (parts.size() > 2 && (!parseInt(parts[2], &options->frames) || options->frames <= 0))
    return Status::Error(spec + ": frames '" + parts[2] + "' is not a positive integer");
  // No count: the length the preset is meant for (300 for the room presets, both laps of "loop").
  if (parts.size() <= 2 && presetDefaultFrames(options->preset) > 0) options->frames = presetDefaultFrames(options->preset);
  return validate(*options).withContext(spec);
}

void enableKinectNoise(SynthOptions* options) {
  options->depth_noise = true;
  options->depth_noise_k = 0.0014;
  options->depth_edge_holes = true;
  options->pixel_noise_sigma = 1.0;
}

Status openSynthSpec(const std::string& spec, bool kinect_noise, std::unique_ptr<SyntheticSource>* out) {
  SynthOptions options;
  PLUMB_RETURN_IF_ERROR(parseSynthSpec(spec, &options));
  if (kinect_noise) enableKinectNoise(&options);
  return SyntheticSource::create(options, out).withContext(spec);
}

std::vector<StampedPose> syntheticGroundTruth(const SyntheticScene& scene, long frames) {
  std::vector<StampedPose> gt;
  gt.reserve(std::size_t(std::max(0L, frames)));
  for (long i = 0; i < frames; ++i) {
    StampedPose p;
    p.timestamp = scene.timestamp(int(i));
    p.T_world_cam = scene.T_world_cam(int(i));
    gt.push_back(p);
  }
  return gt;
}

}  // namespace plumb
