#include "drivers/dataset/camera_presets.h"


#include "drivers/dataset/camera_file.h"
#include "platform/input_file.h"

namespace plumb {
namespace {

PinholeCamera kinect640(double fx, double fy, double cx, double cy) {
  PinholeCamera camera;
  // The Kinect-class colour sensor is a rolling shutter; at VGA 30 Hz its rows are read over
  // most of the 33 ms frame (docs/ODOMETRY.md: the trajectory error is flat for 17-27 ms).
  camera.rolling_shutter_readout_s = 0.025;
  camera.fx = fx;
  camera.fy = fy;
  camera.cx = cx;
  camera.cy = cy;
  camera.width = 640;
  camera.height = 480;
  camera.depth_factor = 5000.0;
  return camera;
}

void setDistortion(PinholeCamera* camera, double k1, double k2, double p1, double p2, double k3) {
  camera->k1 = k1;
  camera->k2 = k2;
  camera->p1 = p1;
  camera->p2 = p2;
  camera->k3 = k3;
}

}  // namespace

Status cameraPreset(const std::string& name, PinholeCamera* out) {
  // Values: TUM RGB-D benchmark calibration page (ROS default model, depth registered to colour),
  // ICL-NUIM's TUM-format release.
  if (name == "tum1") {
    *out = kinect640(517.306408, 516.469215, 318.643040, 255.313989);
    setDistortion(out, 0.262383, -0.953104, -0.005358, 0.002628, 1.163314);
  } else if (name == "tum2") {
    *out = kinect640(520.908620, 521.007327, 325.141442, 249.701764);
    setDistortion(out, 0.231222, -0.784899, -0.003257, -0.000105, 0.917205);
  } else if (name == "tum3") {
    *out = kinect640(535.4, 539.2, 320.1, 247.6);
  } else if (name == "icl") {
    *out = kinect640(481.2, -480.0, 319.5, 239.5);
    out->rolling_shutter_readout_s = 0.0;  // rendered images: global shutter
  } else {
    return Status::Error("unknown camera preset '" + name + "' (known: tum1 tum2 tum3 icl)");
  }
  return Status::Ok();
}

bool isCameraPresetName(const std::string& name) {
  return name == "tum1" || name == "tum2" || name == "tum3" || name == "icl";
}

Status cameraFromSpec(const std::string& preset_or_file, PinholeCamera* out) {
  if (preset_or_file.empty()) return Status::Error("empty camera specification");
  PinholeCamera camera;
  if (isCameraPresetName(preset_or_file)) {
    PLUMB_RETURN_IF_ERROR(cameraPreset(preset_or_file, &camera));
  } else {
    // stat(), not open(): a FIFO must not block here; readCameraFile says what is wrong with it.
    if (pathKind(preset_or_file) == PathKind::kMissing)
      return Status::Error("camera '" + preset_or_file +
                           "' is neither a preset (tum1 tum2 tum3 icl) nor an existing camera file");
    PLUMB_RETURN_IF_ERROR(readCameraFile(preset_or_file, &camera));
  }
  const std::string problem = camera.validate();
  if (!problem.empty()) return Status::Error("camera " + preset_or_file + ": " + problem);
  *out = camera;
  return Status::Ok();
}

}  // namespace plumb
