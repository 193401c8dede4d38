#pragma once
// Camera presets of the public RGB-D benchmarks and the `--camera` specification.
//
//   tum1  Freiburg 1 Kinect (benchmark calibration, with Brown-Conrady distortion)
//   tum2  Freiburg 2 Kinect (with distortion)
//   tum3  Freiburg 3 Asus Xtion (images already undistorted: no distortion)
//   icl   ICL-NUIM in TUM format: fx 481.2, fy -480 (negative: the only value consistent with
//         its TUM-format ground truth), cx 319.5, cy 239.5
// All are 640x480 with depth factor 5000 (raw units per metre).
#include <string>

#include "sensor/camera.h"
#include "platform/status.h"

namespace plumb {

// True for tum1, tum2, tum3, icl.
bool isCameraPresetName(const std::string& name);

// Fills *out with a named preset (tum1, tum2, tum3, icl). Error lists the known names.
Status cameraPreset(const std::string& name, PinholeCamera* out);

// `preset_or_file` is a preset name, or else the path of a camera file (see camera_file.h).
// The result is always validated (PinholeCamera::validate()).
Status cameraFromSpec(const std::string& preset_or_file, PinholeCamera* out);

}  // namespace plumb
