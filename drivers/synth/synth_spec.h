#pragma once
// The one parser of synthetic source specs: synth:PRESET[:SEED[:FRAMES]] (openFrameSource, `plumb
// run --synth-noise`, tests). Kinect-like noise is an option of the parse, not a second parser.
#include <memory>
#include <string>
#include <vector>

#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/trajectory_io.h"
#include "platform/status.h"

namespace plumb {

// True when `spec` names a synthetic scene (starts with "synth:").
bool isSynthSpec(const std::string& spec);

// Fills options->preset/seed/frames from the spec (other fields untouched) and validates. Without
// FRAMES, frames = presetDefaultFrames(PRESET) (300; "loop" 1200, "repeated" 900).
Status parseSynthSpec(const std::string& spec, SynthOptions* options);

// Kinect-like sensor noise: axial depth noise sigma = 0.0014 z^2, holes on the far side of depth
// edges, and 1 grey level of pixel noise.
void enableKinectNoise(SynthOptions* options);

// parseSynthSpec, optionally enableKinectNoise, then the source.
Status openSynthSpec(const std::string& spec, bool kinect_noise, std::unique_ptr<SyntheticSource>* out);

// Exact ground truth (T_world_cam per frame) of the first `frames` frames a scene renders.
std::vector<StampedPose> syntheticGroundTruth(const SyntheticScene& scene, long frames);

}  // namespace plumb
